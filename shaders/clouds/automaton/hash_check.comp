#version 430
// Test helper: evaluates shaders/lib/hash.glsl for given inputs so tests compare it with numpy.
layout(local_size_x = 64) in;

#include "lib/hash.glsl"

layout(std430, binding = 0) readonly buffer Inputs { uvec4 inputs[]; };   // counter, seed, step, stream
layout(std430, binding = 1) writeonly buffer Outputs { uvec2 outputs[]; }; // lowbias32(counter), hash4

uniform uint u_count;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) {
        return;
    }
    uvec4 v = inputs[i];
    outputs[i] = uvec2(atmos_lowbias32(v.x), atmos_hash4(v.x, v.y, v.z, v.w));
}
