#version 430
// The multiple-scattering LUT Ψms (plugins/sky/atmosphere.py: multiscattering_lut): per texel (mu_s, r)
// the second order L2 and the transfer f averaged over ATM_MS_DIRS² directions, Ψ = L2 / (1 − f).
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) writeonly uniform image2D lut;
#include "sky/atmosphere.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= ATM_MS_SIZE || p.y >= ATM_MS_SIZE) return;
    float n = float(ATM_MS_SIZE);
    vec2 x = vec2(p) / (n - 1.0);                  // texel centre -> [0, 1] (from_sub_uv)
    float t = 2.0 * x.x - 1.0;
    float mu_s = sign(t) * t * t;                  // squashed toward the horizon (ms_mu_s)
    float r = atm_clamp_radius(atm_rg + x.y * (atm_rt - atm_rg));
    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    vec3 l2 = vec3(0.0), f = vec3(0.0);
    for (int j = 0; j < ATM_MS_DIRS; j++) {
        float mu = 1.0 - 2.0 * (float(j) + 0.5) / float(ATM_MS_DIRS);
        for (int i = 0; i < ATM_MS_DIRS; i++) {
            float cos_az = cos(2.0 * ATM_PI * (float(i) + 0.5) / float(ATM_MS_DIRS));
            float nu = mu * mu_s + sqrt(max(1.0 - mu * mu, 0.0)) * cos_az * sin_s;
            vec3 transfer;
            l2 += atm_integrate(r, mu, mu_s, nu, ATM_MS_STEPS, true, transfer);
            f += transfer;
        }
    }
    float count = float(ATM_MS_DIRS * ATM_MS_DIRS);
    imageStore(lut, p, vec4(l2 / count / (1.0 - min(f / count, vec3(0.999))), 1.0));
}
