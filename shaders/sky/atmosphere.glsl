// The physical atmosphere after Hillaire 2020: medium, geometry, LUT mappings and the ray march.
// float64 reference: plugins/sky/atmosphere.py (read its docstring); uniforms set by
// plugins/sky/luts.py:set_atmosphere_uniforms; sizes and step counts passed as defines.
#include "lib/exp_mean.glsl"
uniform float atm_rg;          // planet radius, m
uniform float atm_rt;          // top of the atmosphere, m
uniform float atm_hr;          // Rayleigh scale height
uniform float atm_hm;          // Mie scale height
uniform float atm_oz_c;        // ozone tent: centre altitude, half width
uniform float atm_oz_w;
uniform float atm_g;           // Mie HG asymmetry
uniform float atm_ms;          // weight of the multiple-scattering term
uniform vec3 atm_ray;          // Rayleigh scattering, 1/m
uniform vec3 atm_mie_s;        // Mie scattering
uniform vec3 atm_mie_t;        // Mie extinction
uniform vec3 atm_ozone;        // ozone absorption
uniform vec3 atm_albedo;       // ground albedo
uniform vec3 atm_sun;          // sun irradiance (sun_intensity × sun_color)
layout(binding = 10) uniform sampler2D atm_transmittance;
layout(binding = 11) uniform sampler2D atm_multiscattering;

const float ATM_PI = 3.14159265358979;

// (σs Rayleigh, σs Mie) out, σt returned, at radius r.
vec3 atm_coefficients(float r, out vec3 s_ray, out vec3 s_mie) {
    float h = max(r - atm_rg, 0.0);
    float dr = exp(-h / atm_hr);
    float dm = exp(-h / atm_hm);
    float dz = max(0.0, 1.0 - abs(h - atm_oz_c) / atm_oz_w);
    s_ray = atm_ray * dr;
    s_mie = atm_mie_s * dm;
    return s_ray + atm_mie_t * dm + atm_ozone * dz;
}

float atm_discriminant(float radius, float r, float mu) { return (radius - r) * (radius + r) + (r * mu) * (r * mu); }
float atm_distance_to_top(float r, float mu) { return max(-r * mu + sqrt(max(atm_discriminant(atm_rt, r, mu), 0.0)), 0.0); }
float atm_distance_to_ground(float r, float mu) { return max(-r * mu - sqrt(max(atm_discriminant(atm_rg, r, mu), 0.0)), 0.0); }
bool atm_hits_ground(float r, float mu) { return mu < 0.0 && atm_discriminant(atm_rg, r, mu) >= 0.0; }
float atm_ray_end(float r, float mu) { return atm_hits_ground(r, mu) ? atm_distance_to_ground(r, mu) : atm_distance_to_top(r, mu); }
float atm_horizon_mu(float r) { return -sqrt(max((r - atm_rg) * (r + atm_rg), 0.0)) / r; }
float atm_clamp_radius(float r) { return clamp(r, atm_rg + ATM_RADIUS_EPS, atm_rt - ATM_RADIUS_EPS); }

float atm_sun_visibility(float r, float mu_s) {
    return smoothstep(0.0, 1.0, clamp((mu_s - atm_horizon_mu(r)) / ATM_SUN_EDGE * 0.5 + 0.5, 0.0, 1.0));
}

float atm_to_sub_uv(float x, float n) { return 0.5 / n + x * (1.0 - 1.0 / n); }
float atm_from_sub_uv(float u, float n) { return (u - 0.5 / n) / (1.0 - 1.0 / n); }

vec2 atm_transmittance_uv(float r, float mu) {
    float H = sqrt(atm_rt * atm_rt - atm_rg * atm_rg);
    float rho = sqrt(max((r - atm_rg) * (r + atm_rg), 0.0));
    float d = atm_distance_to_top(r, mu);
    float d_min = atm_rt - r, d_max = rho + H;
    float x_mu = d_max > d_min ? (d - d_min) / max(d_max - d_min, 1e-9) : 0.0;
    return vec2(atm_to_sub_uv(clamp(x_mu, 0.0, 1.0), float(ATM_T_W)), atm_to_sub_uv(clamp(rho / H, 0.0, 1.0), float(ATM_T_H)));
}

// T to the top toward the sun × the planet's soft shadow.
vec3 atm_transmittance_to_sun(float r, float mu_s) {
    vec2 uv = atm_transmittance_uv(r, max(mu_s, atm_horizon_mu(r)));
    return exp(-texture(atm_transmittance, uv).rgb) * atm_sun_visibility(r, mu_s);   // the LUT holds τ
}

vec2 atm_ms_uv(float r, float mu_s) {
    float n = float(ATM_MS_SIZE);
    mu_s = clamp(mu_s, -1.0, 1.0);          // the u axis is squashed toward the horizon (reference: ms_mu_s)
    return vec2(atm_to_sub_uv(clamp(0.5 * sign(mu_s) * sqrt(abs(mu_s)) + 0.5, 0.0, 1.0), n),
                atm_to_sub_uv(clamp((r - atm_rg) / (atm_rt - atm_rg), 0.0, 1.0), n));
}

// The point t metres along the ray from radius r (zenith cosine mu; sun at mu_s, nu = cos view·sun):
// its radius and the sun's zenith cosine there.
vec2 atm_point(float r, float mu, float mu_s, float nu, float t) {
    float ri = sqrt(max(r * r + t * t + 2.0 * r * mu * t, 0.0));
    return vec2(ri, clamp((r * mu_s + t * nu) / max(ri, 1.0), -1.0, 1.0));
}

float atm_rayleigh_phase(float nu) { return 3.0 / (16.0 * ATM_PI) * (1.0 + nu * nu); }
float atm_hg_phase(float g, float nu) { return (1.0 - g * g) / (4.0 * ATM_PI * pow(1.0 + g * g - 2.0 * g * nu, 1.5)); }

// The (Rayleigh, Mie) phase of a ray with nu = cos view·sun; `isotropic`: the multiple-scattering LUT's
// pass (isotropic phase, no Ψ). Once per ray: atm_segment takes it.
vec2 atm_phases(float nu, bool isotropic) {
    return isotropic ? vec2(0.25 / ATM_PI) : vec2(atm_rayleigh_phase(nu), atm_hg_phase(atm_g, nu));
}

// One segment [t0, t1] of a ray from radius r (zenith cosine mu; sun at mu_s, nu = cos view·sun; `phases`
// its atm_phases), sampled at its middle (the medium's coefficients there, the sun's transmittance, the
// multiple-scattering LUT unless `isotropic`): adds its in-scattered radiance and transfer (∫ σs T dt)
// seen through `throughput`, then dims `throughput` by the segment. atm_march's step;
// sky/aerial_volume.comp marches slice by slice.
void atm_segment(float r, float mu, float mu_s, float nu, float t0, float t1, vec2 phases, bool isotropic,
                 inout vec3 radiance, inout vec3 transfer, inout vec3 throughput) {
    float pr = phases.x, pm = phases.y;
    float t = 0.5 * (t0 + t1), dt = t1 - t0;
    vec2 at = atm_point(r, mu, mu_s, nu, t);
    float ri = at.x, mus_i = at.y;
    vec3 s_ray, s_mie;
    vec3 ext = atm_coefficients(ri, s_ray, s_mie);
    vec3 seg = exp(-ext * dt);
    vec3 spread = dt * exp_mean(ext * dt);    // ∫ e^(−σt s) ds over dt
    vec3 source = atm_transmittance_to_sun(ri, mus_i) * (s_ray * pr + s_mie * pm);
    if (!isotropic && atm_ms > 0.0)
        source += atm_ms * texture(atm_multiscattering, atm_ms_uv(ri, mus_i)).rgb * (s_ray + s_mie);
    radiance += throughput * source * spread;
    transfer += throughput * (s_ray + s_mie) * spread;
    throughput *= seg;
}

// In-scattered radiance (per unit sun: times atm_sun for the real sun) along the first t_max metres of
// the ray from radius r (zenith cosine mu; sun at mu_s, nu = cos view·sun), `steps` quadratically spaced
// segments; `isotropic`: the multiple-scattering LUT's pass (isotropic phase, no Ψ). `transfer`:
// ∫ σs T dt; `throughput`: the ray's transmittance over t_max.
vec3 atm_march(float r, float mu, float mu_s, float nu, float t_max, int steps, bool isotropic,
               out vec3 transfer, out vec3 throughput) {
    vec3 radiance = vec3(0.0);
    throughput = vec3(1.0);
    transfer = vec3(0.0);
    vec2 phases = atm_phases(nu, isotropic);
    for (int i = 0; i < steps; i++) {
        float a = float(i) / float(steps), b = float(i + 1) / float(steps);
        atm_segment(r, mu, mu_s, nu, t_max * a * a, t_max * b * b, phases, isotropic, radiance, transfer, throughput);
    }
    return radiance;
}

// Radiance along the whole ray from radius r to the top of the atmosphere or the ground (whose sunlit
// albedo it adds): atm_march to the end; `transfer` as there.
vec3 atm_integrate(float r, float mu, float mu_s, float nu, int steps, bool isotropic, out vec3 transfer) {
    r = atm_clamp_radius(r);
    bool ground = atm_hits_ground(r, mu);
    float t_max = atm_ray_end(r, mu);
    vec3 throughput;
    vec3 radiance = atm_march(r, mu, mu_s, nu, t_max, steps, isotropic, transfer, throughput);
    if (ground) {
        float mu_g = clamp((r * mu_s + t_max * nu) / atm_rg, -1.0, 1.0);
        radiance += throughput * atm_transmittance_to_sun(atm_rg + ATM_RADIUS_EPS, mu_g) * max(mu_g, 0.0) * atm_albedo / ATM_PI;
    }
    return radiance * (isotropic ? vec3(1.0) : atm_sun);
}

// Aerial perspective: the sunlight scattered toward the camera over the first `distance` metres of the
// ray (capped at the atmosphere's end), and the ray's transmittance over them (Hillaire 2020 sec. 5.5,
// marched per pixel instead of a froxel volume).
vec3 atm_aerial(float r, float mu, float mu_s, float nu, float distance, int steps, out vec3 transmittance) {
    r = atm_clamp_radius(r);
    vec3 transfer;
    return atm_march(r, mu, mu_s, nu, min(distance, atm_ray_end(r, mu)), steps, false, transfer, transmittance) * atm_sun;
}

// Sky-view LUT: (u, v) <-> (view mu, cos azimuth from the sun) seen from radius r.
vec2 atm_sky_view_uv(float r, float mu, float cos_az) {
    float beta = atan(atm_rg, sqrt(max((r - atm_rg) * (r + atm_rg), 0.0)));   // the horizon's depression from the nadir
    float zh = ATM_PI - beta;
    mu = clamp(mu, -1.0, 1.0);
    float theta = 2.0 * atan(sqrt(max(1.0 - mu, 0.0)), sqrt(max(1.0 + mu, 0.0)));
    float xv = theta < zh ? 0.5 * (1.0 - sqrt(max(1.0 - theta / zh, 0.0)))
                          : 0.5 + 0.5 * sqrt(max((theta - zh) / max(beta, 1e-9), 0.0));
    float xu = sqrt(clamp(0.5 * (1.0 - cos_az), 0.0, 1.0));
    return vec2(atm_to_sub_uv(xu, float(ATM_SV_W)), atm_to_sub_uv(clamp(xv, 0.0, 1.0), float(ATM_SV_H)));
}
