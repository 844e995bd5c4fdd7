#version 430
// One tileable detail-noise texture (plugins/clouds/raymarch/noise.py; float64 reference:
// noise_reference.py). Texel j holds the noise at tile coordinate u = (j + 0.5) / size; every layer is
// periodic over the tile, so the texture repeats without a seam. Worley W = 1 - clamp(F1, 0, 1) (one
// hashed feature point per cell of a periodic lattice), Worley FBM = .625 W_f + .25 W_2f + .125 W_4f,
// Perlin FBM = clamp(.5 + .5 PERLIN_GAIN (4 n_f + 2 n_2f + n_4f) / 7), Perlin–Worley = (P + W) / (1 + W);
// stored contrast-stretched: stretch(v, range) = clamp((v - range.x) / (range.y - range.x), 0, 1).
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
#include "lib/gradient_noise.glsl"

layout(rgba8, binding = 0) writeonly uniform image3D noise_volume;
uniform int size;
uniform uint seed;
uniform int texture_index;      // 0 base, 1 detail: part of every layer's hash stream
uniform int perlin_frequency;   // > 0: R = Perlin–Worley, GBA = the Worley FBMs; 0: RGB = them, A = 1
uniform ivec3 worley_frequency; // cells per tile of each Worley FBM's first octave

// NOISE_RULE (uint), PERLIN_GAIN (float), PW_RANGE and WORLEY_RANGE (vec2) are defines from noise.py.

uvec2 layer_key(int perlin, int channel, int octave) {
    return atmos_stream_key(seed, 0u, NOISE_RULE, uint(texture_index * 64 + perlin * 32 + channel * 4 + octave));
}

// 1 - clamp(F1, 0, 1) at lattice coordinate q >= 0 of a lattice with `period` cells per side.
float worley(vec3 q, int period, uvec2 key) {
    ivec3 cell = ivec3(floor(q));
    float best = 1e9;
    for (int z = -1; z <= 1; ++z)
        for (int y = -1; y <= 1; ++y)
            for (int x = -1; x <= 1; ++x) {
                ivec3 n = cell + ivec3(x, y, z);
                ivec3 w = (n + period) % period;
                uint h = atmos_hash_counter(uint(w.x + period * (w.y + period * w.z)), key);
                vec3 point = vec3(n) + (vec3(uvec3(h, h >> 10, h >> 20) & 1023u) + 0.5) / 1024.0;
                vec3 d = q - point;
                best = min(best, dot(d, d));
            }
    return 1.0 - clamp(sqrt(best), 0.0, 1.0);
}

float worley_fbm(vec3 u, int f, int channel) {
    return 0.625 * worley(u * float(f), f, layer_key(0, channel, 0))
         + 0.25 * worley(u * float(2 * f), 2 * f, layer_key(0, channel, 1))
         + 0.125 * worley(u * float(4 * f), 4 * f, layer_key(0, channel, 2));
}

float perlin_fbm(vec3 u, int f) {
    float n = (4.0 * periodic_gradient_noise(u * float(f), f, layer_key(1, 0, 0))
             + 2.0 * periodic_gradient_noise(u * float(2 * f), 2 * f, layer_key(1, 0, 1))
             + periodic_gradient_noise(u * float(4 * f), 4 * f, layer_key(1, 0, 2))) / 7.0;
    return clamp(0.5 + 0.5 * PERLIN_GAIN * n, 0.0, 1.0);
}

float stretch(float v, vec2 range) {
    return clamp((v - range.x) / (range.y - range.x), 0.0, 1.0);
}

void main() {
    ivec3 j = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(j, ivec3(size)))) return;
    vec3 u = (vec3(j) + 0.5) / float(size);
    vec3 w = vec3(worley_fbm(u, worley_frequency.x, 0), worley_fbm(u, worley_frequency.y, 1),
                  worley_fbm(u, worley_frequency.z, 2));
    vec3 ws = vec3(stretch(w.x, WORLEY_RANGE), stretch(w.y, WORLEY_RANGE), stretch(w.z, WORLEY_RANGE));
    vec4 value = vec4(ws, 1.0);
    if (perlin_frequency > 0) {
        float p = perlin_fbm(u, perlin_frequency);
        value = vec4(stretch(clamp((p + w.x) / (1.0 + w.x), 0.0, 1.0), PW_RANGE), ws);
    }
    imageStore(noise_volume, j, value);
}
