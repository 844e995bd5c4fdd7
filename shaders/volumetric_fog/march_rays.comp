#version 430
// Test helper: fog_march for `count` rays (origin, direction, limit) into vec4 results (the sun: the frame block).
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
#include "volumetric_fog/medium.glsl"
layout(local_size_x = 16) in;
struct Ray { vec4 origin_limit; vec4 dir; };
layout(std430, binding = 0) readonly buffer Rays { Ray rays[]; };
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; };
uniform uint count;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    results[i] = fog_march(rays[i].origin_limit.xyz, normalize(rays[i].dir.xyz), rays[i].origin_limit.w);
}
