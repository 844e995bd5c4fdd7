// Periodic 3D gradient noise (Perlin's improved noise: 12 edge gradients, quintic fade) whose integer
// lattice wraps with `period`, so a volume of period^3 cells tiles seamlessly. Lattice gradients come
// from lib/hash.glsl exactly as atmos/gradient_noise.py computes them (same counter and key).
#include "lib/hash.glsl"

const vec3 NOISE_GRADIENTS[12] = vec3[12](
    vec3(1, 1, 0), vec3(-1, 1, 0), vec3(1, -1, 0), vec3(-1, -1, 0),
    vec3(1, 0, 1), vec3(-1, 0, 1), vec3(1, 0, -1), vec3(-1, 0, -1),
    vec3(0, 1, 1), vec3(0, -1, 1), vec3(0, 1, -1), vec3(0, -1, -1));

float gradient_corner(ivec3 cell, ivec3 corner, vec3 f, int period, uvec2 key) {
    ivec3 w = (cell + corner) % period;
    uint counter = uint(w.x + period * (w.y + period * w.z));
    return dot(NOISE_GRADIENTS[atmos_hash_counter(counter, key) % 12u], f - vec3(corner));
}

// Noise at lattice coordinate q (any real vector), in about [-1, 1]; period(q + period * e) == noise(q).
float periodic_gradient_noise(vec3 q, int period, uvec2 key) {
    float p = float(period);
    q = q - p * floor(q / p);                 // wrap first: cell indices stay small and non-negative
    vec3 c = floor(q);
    vec3 f = q - c;
    ivec3 i = ivec3(c);
    vec3 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    float x00 = mix(gradient_corner(i, ivec3(0, 0, 0), f, period, key), gradient_corner(i, ivec3(1, 0, 0), f, period, key), u.x);
    float x10 = mix(gradient_corner(i, ivec3(0, 1, 0), f, period, key), gradient_corner(i, ivec3(1, 1, 0), f, period, key), u.x);
    float x01 = mix(gradient_corner(i, ivec3(0, 0, 1), f, period, key), gradient_corner(i, ivec3(1, 0, 1), f, period, key), u.x);
    float x11 = mix(gradient_corner(i, ivec3(0, 1, 1), f, period, key), gradient_corner(i, ivec3(1, 1, 1), f, period, key), u.x);
    return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z);
}
