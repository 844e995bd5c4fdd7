#version 430
// Test/benchmark helper: value_fbm at `count` points (vec4 xyz_ SSBO 0) into floats (SSBO 1); with
// FOG_LATTICE defined, the volumetric fog's lattice_fbm instead (volumetric_fog/lattice.glsl, its
// lattice bound as fog_lattice).
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
#ifdef FOG_LATTICE
#include "volumetric_fog/lattice.glsl"
#else
uniform uint seed;
#endif
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 1) writeonly buffer Values { float values[]; };
uniform uint count;
uniform int octaves;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
#ifdef FOG_LATTICE
    values[i] = lattice_fbm(points[i].xyz, octaves);
#else
    values[i] = value_fbm(points[i].xyz, octaves, vn_key(seed));
#endif
}
