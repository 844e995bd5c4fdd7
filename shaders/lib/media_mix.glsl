// Two media on one ray, each alone giving (in-scattered light L, grey transmittance T), mixed in
// proportion (their extinctions in one ratio all along the ray: exact for two homogeneous media; float64
// twin atmos/composition.py media_mix): together they transmit T_a T_b and scatter
//   (1 - T_a T_b) / (tau_a + tau_b) * (L_a tau_a / (1 - T_a) + L_b tau_b / (1 - T_b)),   tau = -ln T,
// each medium's light per unit optical depth weighted by its share of the whole. Either alone (T = 1,
// L = 0 for the other) gives itself back.
#include "lib/exp_mean.glsl"

vec3 media_mix(vec4 a, vec4 b) {
    float ta = -log(clamp(a.a, 1e-30, 1.0)), tb = -log(clamp(b.a, 1e-30, 1.0)), total = ta + tb;
    return exp_mean(total) * (a.rgb / exp_mean(ta) + b.rgb / exp_mean(tb));
}
