#version 430
// lib/froxel_slices.glsl froxel_jitter at each frame of `frames` (tests/test_froxel_history.py).
#include "lib/froxel_slices.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Frames { uint frames[]; };
layout(std430, binding = 1) writeonly buffer Jitters { float jitters[]; };
uniform int count;
uniform int jittered;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < uint(count)) jitters[i] = froxel_jitter(frames[i], jittered != 0);
}
