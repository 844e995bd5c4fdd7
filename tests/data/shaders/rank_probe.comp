#version 430
// field.glsl's fbm_rank at given fbm values and mip levels (tests/test_far_rank_table.py).
layout(local_size_x = 64) in;
#include "clouds/far_field/field.glsl"
layout(std430, binding = 1) readonly buffer Fbm { vec4 fbm[]; };
layout(std430, binding = 2) readonly buffer Lods { float lods[]; };
layout(std430, binding = 3) writeonly buffer Ranks { vec4 ranks[]; };
uniform int count;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < uint(count)) ranks[i] = fbm_rank(fbm[i], lods[i]);
}
