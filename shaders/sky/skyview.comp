#version 430
// The sky-view LUT (plugins/sky/atmosphere.py: sky_view_lut): the radiance seen from radius `view_r`
// for a sun at height `sun_mu`, over (azimuth from the sun, view zenith squashed toward the horizon).
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32f, binding = 0) writeonly uniform image2D lut;
uniform float view_r;
uniform float sun_mu;
#include "sky/atmosphere.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= ATM_SV_W || p.y >= ATM_SV_H) return;
    vec2 x = clamp(vec2(p) / vec2(ATM_SV_W - 1, ATM_SV_H - 1), 0.0, 1.0);   // from_sub_uv of the texel centre
    float r = view_r;
    float beta = atan(atm_rg, sqrt(max((r - atm_rg) * (r + atm_rg), 0.0)));
    float zh = ATM_PI - beta;
    float theta = x.y < 0.5 ? zh * (1.0 - (1.0 - 2.0 * x.y) * (1.0 - 2.0 * x.y)) : zh + beta * (2.0 * x.y - 1.0) * (2.0 * x.y - 1.0);
    float mu = cos(theta);
    float cos_az = 1.0 - 2.0 * x.x * x.x;
    float nu = mu * sun_mu + sqrt(max(1.0 - mu * mu, 0.0)) * cos_az * sqrt(max(1.0 - sun_mu * sun_mu, 0.0));
    vec3 transfer;
    imageStore(lut, p, vec4(atm_integrate(r, mu, sun_mu, nu, ATM_SV_STEPS, false, transfer), 1.0));
}
