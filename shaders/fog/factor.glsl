// The fog factor f of Zdrojewska's eq. (2)-(4), (6), (7) for a point at distance d along the ray from
// `eye` toward `world`; the one source of f for the post-process pass and apply_fog (plugins/fog/factors.py
// is its float64 reference). FOG_MODE: 0 linear, 1 exp, 2 exp2, 3 hetero_exp, 4 hetero_exp2, 5 height,
// 6 hetero_height. Height fog: density g e^(-(y - base)/H), its optical depth along the straight ray in
// closed form, g e^(-(y_low - base)/H) d exp_mean(|y1 - y0| / H), taken in logs (no overflow at any height).
uniform float fog_density;   // g
uniform float fog_start;
uniform float fog_end;

#define FOG_HETERO (FOG_MODE == 3 || FOG_MODE == 4 || FOG_MODE == 6)
#if FOG_MODE >= 5
#include "lib/exp_mean.glsl"
uniform float fog_height_base;   // m: where the density is g
uniform float fog_scale_height;  // m over which it thins by e
#endif

#if FOG_HETERO
#include "lib/gradient_noise.glsl"
uniform float fog_time;       // seconds; octave i is displaced by fog_wind[i] * fog_time
uniform float fog_tile;       // metres covered by one noise tile
uniform float fog_amplitude;  // grey-scale range of an octave: noise_i = 0.5 + 0.5 * amplitude * n
uniform int fog_period[4];    // lattice cells per tile (the octave's "resolution")
uniform uvec2 fog_key[4];
uniform vec3 fog_wind[4];
uniform vec2 fog_turn[4];     // (cos, sin) of the octave's turn about y
#if !FOG_PROCEDURAL
layout(binding = 3) uniform sampler3D fog_noise[4];
#endif

// Perlin turbulence, eq. (5): sum over octaves of noise_i(x) / 2^i with noise_i in [0, 1].
float fog_turbulence(vec3 world) {
    float sum = 0.0;
    float weight = 1.0;
    for (int i = 0; i < FOG_OCTAVES; ++i) {
        vec3 p = world - fog_wind[i] * fog_time;
        vec2 cs = fog_turn[i];
        vec3 u = vec3(cs.x * p.x - cs.y * p.z, p.y, cs.y * p.x + cs.x * p.z) / fog_tile;
#if FOG_PROCEDURAL
        float n = periodic_gradient_noise(u * float(fog_period[i]), fog_period[i], fog_key[i]);
#else
        float n = texture(fog_noise[i], u).r;
#endif
        sum += clamp(0.5 + 0.5 * fog_amplitude * n, 0.0, 1.0) * weight;
        weight *= 0.5;
    }
    return sum;
}
#endif

float fog_factor(float d, vec3 world, vec3 eye) {
    d = clamp(d, 0.0, 3e38);                  // +inf (sky) -> huge; never inf * 0
#if FOG_MODE == 0
    return clamp((fog_end - d) / (fog_end - fog_start), 0.0, 1.0);      // eq. (2)
#else
    float g = fog_density;
#if FOG_HETERO
    g *= fog_turbulence(world);                                          // eq. (6), (7)
#endif
    if (!(g > 0.0)) return 1.0;                                          // no medium: no fog
#if FOG_MODE >= 5
    vec3 toward = world - eye;
    float slope = toward.y / max(length(toward), 1e-30);                 // dy per metre along the ray
    float y0 = eye.y, y1 = eye.y + slope * d;
    float path = d * exp_mean(abs(y1 - y0) / fog_scale_height);          // ∫ e^(-(y - y_low)/H) ds
    if (!(path > 0.0)) return 1.0;                                       // no path: no fog
    float log_tau = log(g) - (min(y0, y1) - fog_height_base) / fog_scale_height + log(max(path, 1e-37));
    float x = exp(min(log_tau, log(1e4)));
#else
    float x = min(d * g, 1e4);
#endif
#if FOG_MODE == 2 || FOG_MODE == 4
    x = x * x;                                                           // eq. (4), (7)
#endif
    return clamp(exp(-x), 0.0, 1.0);                                     // eq. (3), (6)
#endif
}
