// What the light shafts' march (light_shafts/march.comp) and froxels (light_shafts/froxels.comp) share:
// their uniforms and the terms of one sample at distance s along a view ray `dir` (the formulas are in
// march.comp's header). view_basis, camera_pos, near, far, sun_dir: the frame block (lib/frame.glsl).
#include "lib/frame.glsl"
#include "lib/hdr_max.glsl"
#include "lib/view_ray.glsl"
#include "lib/phase.glsl"
#if SHAFT_EXACT_SHADOWS
#include "clouds/volume/column.glsl"
#define SUN_TAU sun_optical_depth
#else
#include "clouds/shadows/shadow_map.glsl"
#define SUN_TAU cloud_shadow_tau
#endif
uniform vec3 irradiance;       // sun_intensity * Sun.color * horizon fade, at most float32's largest
uniform vec3 lobes;            // phase_g, phase_g2, phase_w
uniform float scattering;      // 1/m
uniform float max_distance;
uniform int has_clouds;
#if SHAFT_FOG || SHAFT_AERIAL
#include "lib/cloud_distance.glsl"
uniform int has_cloud_distance;   // 1: cloud_distance is bound
layout(binding = 3) uniform sampler2D cloud_distance;
#endif
#if SHAFT_FOG
#include "fog/over.glsl"
uniform float fog_sun_share;   // LightShaftSettings.fog_sun_share
#endif
#if SHAFT_AERIAL
#include "sky/atmosphere.glsl"
uniform float view_r;          // the camera's radius from the planet's centre
#endif

// The sun's optical depth through the clouds at p (0 without clouds).
float shaft_sun_tau(vec3 p) {
    return has_clouds != 0 ? SUN_TAU(p, sun_dir) : 0.0;
}

#if SHAFT_FOG
// The fog's own distance along `dir` for a pixel whose scene distance is d (z: its depth): the scene's,
// the sky's far plane, or (sky "keep") the ground plane's below the horizon (fog.comp) and max_distance
// above it: a kept sky holds the air's haze already (the fog adds none there), and the clouds' shadow
// takes the fog's sunlit in-scatter out of it over the marched reach (the rays seen against the sky).
float shaft_fog_behind(float z, float d, vec3 dir, float ray_length) {
    return z < 1.0 ? d : (fog_sky_keep == 0 ? far * ray_length
         : (dir.y < 0.0 && camera_pos.y > 0.0 ? camera_pos.y / max(-dir.y, 1e-6) : max_distance));
}
#endif

#if SHAFT_AERIAL
// The air's grey transmittance from the eye to s along `dir` (r: the eye's radius, nu = cos view·sun).
float shaft_air(float r, vec3 dir, float nu, float s) {
    vec3 s_ray, s_mie;
    return dot(exp(-atm_coefficients(atm_point(r, dir.y, sun_dir.y, nu, s).x, s_ray, s_mie) * s), vec3(1.0 / 3.0));
}

// The air's single-scattered sunlight per metre at s, seen from the eye (its transmittance there), per
// unit atm_sun; pr, pm: the Rayleigh and Mie phases of the ray.
vec3 shaft_air_light(float r, vec3 dir, float nu, float s, float pr, float pm) {
    vec2 at = atm_point(r, dir.y, sun_dir.y, nu, s);
    vec3 s_ray, s_mie;
    vec3 ext = atm_coefficients(at.x, s_ray, s_mie);
    return exp(-ext * s) * atm_transmittance_to_sun(at.x, at.y) * (s_ray * pr + s_mie * pm);
}
#endif
