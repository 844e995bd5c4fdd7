#version 430
// Test/benchmark helper: value_fbm at `count` points (vec4 xyz_ SSBO 0) into floats (SSBO 1).
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) writeonly buffer Values { float values[]; };
uniform uint count;
uniform int octaves;
uniform uint seed;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    values[i] = value_fbm(points[i].xyz, octaves, vn_key(seed));
}
