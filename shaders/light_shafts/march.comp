#version 430
// Light shafts marched through the cloud shadow map, at low resolution, one compute invocation per
// low-res texel (written to the image `shafts`): along the view ray of each
// low-res texel (the centre of its block) to the block's farthest scene depth (the sky: max_distance),
// `steps` samples from a jittered start gather the sun light a thin haze scatters toward the eye,
//   L = sum_i scattering * phase(cos) * E * exp(-tau_sun(p_i)) * exp(-scattering * s_i) * ds,
// tau_sun through the clouds from the cloud shadow map, one fetch per step (clouds/shadows/shadow_map.glsl,
// the volume's and the far field's columns; has_clouds 0: none), or with SHAFT_EXACT_SHADOWS from the
// density maps themselves (clouds/volume/column.glsl, with CLOUD_FAR_FIELD the far field's columns too).
// Output (L, T = exp(-scattering * d)), upsampled and composited by core/offscreen_composite.comp:
// rgb = L + T * rgb. plugins/light_shafts/reference.py march_shafts is the same in numpy.
// SHAFT_FOG 1 (a FogPlugin owns the air's in-scattering, so the haze is counted once): no light and no
// extinction of the shafts' own; they take away the fog's in-scatter lost in cloud shadow,
//   L = -fog_sun_share * C_fog(dir) * sum_i w(s_i) [f(s_i) - f(s_i+1)] (1 - V(s_i)),  T = 1,
// f = fog/factor.glsl (at the fog's end point: the sum of [f(s_i) - f(s_i+1)] telescopes to the fog's own
// 1 - f), V = exp(-tau_sun) the sun's visibility through the clouds, w the share of the fog in front of
// s_i (a cloud in front, "cloud_distance": a before it, 1 - a behind). It never exceeds the fog's
// in-scatter (tests/test_light_shafts_fog.py); a sky="keep" sky, which holds the air's haze itself and
// is not fogged, loses the fog's share over the first max_distance (the rays seen against the sky).
// SHAFT_AERIAL 1 (no fog; the sky's aerial perspective owns the air's light, sky/aerial.comp): the same,
// for the atmosphere's single-scattered sunlight, lost where the clouds shadow the air,
//   L = -sum_i w(s_i) T(s_i) E_sun(p_i) [s_ray(p_i) p_R(cos) + s_mie(p_i) p_M(cos)] (1 - V(s_i)) ds,  T = 1,
// T(s) ~ exp(-ext(p) s) the air's transmittance from the eye, E_sun = atm_sun × its transmittance to the
// sun (sky/atmosphere.glsl); w as above with the scene's distance (the clouds hazed at their own).
// Both (a fog under the aerial perspective, mixed along the ray: atmos/composition.py): both sums, each
// medium's in-scatter at s dimmed by the other in front of s too (the fog's by the air's grey
// transmittance exp(-ext s), the air's by the fog's f(s)).
#include "light_shafts/medium.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) writeonly uniform image2D shafts;   // (L, T) per low-res texel
layout(binding = 2) uniform sampler2D low_depth;   // the farthest scene depth of each block
uniform int steps;
uniform int factor;
uniform vec2 frame_size;

// Per-texel start offset in [0, 1): the tiled blue noise (atmos/blue_noise.py; white noise clumped).
layout(binding = 23) uniform sampler2D blue_noise;
float start_jitter(ivec2 q) {
    return texelFetch(blue_noise, q % textureSize(blue_noise, 0), 0).r;
}

vec4 march(ivec2 q) {
    vec2 uv = (vec2(q) + 0.5) * float(factor) / frame_size;
    vec3 ray = view_ray(uv, view_basis);
    vec3 dir = normalize(ray);
    float d = min(view_ray_distance(uv, texelFetch(low_depth, q, 0).r, view_basis, near, far, max_distance),
                  max_distance);
    float j = start_jitter(q);
#if SHAFT_FOG || SHAFT_AERIAL
    vec2 cloud = cloud_cover_distance(has_cloud_distance != 0 ? texture(cloud_distance, uv).rg : vec2(0.0));
    float a = cloud.x, dc = cloud.y;            // the clouds' coverage and own distance
    vec3 taken = vec3(0.0);                     // the in-scatter the clouds' shadow takes away
#endif
#if SHAFT_AERIAL
    float r = atm_clamp_radius(view_r), nu = dot(dir, sun_dir);
#endif
#if SHAFT_FOG
    // the fog's own distance (shaft_fog_behind: the scene's, the far plane's, or under sky "keep" the ground
    // plane's below the horizon and max_distance above it)
    float behind = shaft_fog_behind(texelFetch(low_depth, q, 0).r, d, dir, length(ray));
    float reach = max(behind, a > 0.0 ? dc : 0.0);
    vec3 end = camera_pos + dir * reach;
    float dm = min(reach, max_distance);
    float dsf = dm / float(steps);
    float lost = 0.0;
    float f0 = fog_factor(0.0, end, camera_pos);
    for (int i = 0; i < steps; ++i) {
        float s0 = float(i) * dsf;
        float f1 = fog_factor(s0 + dsf, end, camera_pos);
        float s = s0 + j * dsf;
        float w = (s < dc ? a : 0.0) + (s < behind ? 1.0 - a : 0.0);
        float tau = shaft_sun_tau(camera_pos + dir * s);
        float air = 1.0;                        // the air in front of s (with the aerial perspective)
#if SHAFT_AERIAL
        air = shaft_air(r, dir, nu, s);
#endif
        lost += w * (f0 - f1) * (1.0 - exp(-tau)) * air;
        f0 = f1;
    }
    taken += fog_sun_share * in_color(dir) * lost;
#endif
#if SHAFT_AERIAL
    float reach_air = max(d, a > 0.0 ? min(dc, max_distance) : 0.0);
    float pr = atm_rayleigh_phase(nu), pm = atm_hg_phase(atm_g, nu);
    float dsa = reach_air / float(steps);
    vec3 shadowed = vec3(0.0);
    for (int i = 0; i < steps; ++i) {
        float s = (float(i) + j) * dsa;
        float w = (s < dc ? a : 0.0) + (s < d ? 1.0 - a : 0.0);
        float tau = shaft_sun_tau(camera_pos + dir * s);
        if (w <= 0.0 || tau <= 0.0) continue;
        float fogged = 1.0;                     // the fog in front of s (with a FogPlugin)
#if SHAFT_FOG
        fogged = fog_factor(s, end, camera_pos);
#endif
        shadowed += w * shaft_air_light(r, dir, nu, s, pr, pm) * (1.0 - exp(-tau)) * fogged;
    }
    taken += shadowed * dsa * atm_sun;
#endif
#if SHAFT_FOG || SHAFT_AERIAL
    return vec4(-taken, 1.0);
#endif
    float ds = d / float(steps);
    float sum = 0.0;
    for (int i = 0; i < steps; ++i) {
        float s = (float(i) + j) * ds;
        sum += exp(-shaft_sun_tau(camera_pos + dir * s) - scattering * s);
    }
    vec3 light = irradiance * (scattering * phase2(dot(dir, sun_dir), lobes) * sum * ds);
    return vec4(min(light, vec3(HDR_MAX)), exp(-scattering * d));   // blended onto the float16 colour
}

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(q, imageSize(shafts)))) return;
    imageStore(shafts, q, march(q));
}
