#version 430
// The transmittance LUT (plugins/sky/atmosphere.py: transmittance_lut): the optical depth ∫σt to the top of the
// atmosphere for each texel's (r, mu), ATM_T_STEPS midpoint steps.
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) writeonly uniform image2D lut;
#include "sky/atmosphere.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= ATM_T_W || p.y >= ATM_T_H) return;
    vec2 uv = (vec2(p) + 0.5) / vec2(ATM_T_W, ATM_T_H);
    float x_mu = clamp(atm_from_sub_uv(uv.x, float(ATM_T_W)), 0.0, 1.0);
    float x_r = clamp(atm_from_sub_uv(uv.y, float(ATM_T_H)), 0.0, 1.0);
    float H = sqrt(atm_rt * atm_rt - atm_rg * atm_rg);
    float rho = H * x_r;
    float r = sqrt(rho * rho + atm_rg * atm_rg);
    float d_min = atm_rt - r, d_max = rho + H;
    float d = d_min + x_mu * (d_max - d_min);
    float mu = d == 0.0 ? 1.0 : clamp((H * H - rho * rho - d * d) / max(2.0 * r * d, 1e-9), -1.0, 1.0);
    float len = atm_distance_to_top(r, mu);
    vec3 depth = vec3(0.0);
    for (int i = 0; i < ATM_T_STEPS; i++) {
        float t = (float(i) + 0.5) / float(ATM_T_STEPS) * len;
        vec3 s_ray, s_mie;
        depth += atm_coefficients(sqrt(max(r * r + t * t + 2.0 * r * mu * t, 0.0)), s_ray, s_mie);
    }
    imageStore(lut, p, vec4(depth * (len / float(ATM_T_STEPS)), 1.0));     // τ; T = exp(-τ) after the filter
}
