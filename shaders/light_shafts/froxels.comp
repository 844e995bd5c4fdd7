#version 430
// The light shafts' froxel volume (LightShaftSettings.froxels = (W, H, D)): one invocation per column
// marches the view ray through its centre, uv = ((x, y) + 0.5) / (W, H), one sample in each slice at the
// share froxel_jitter of its depth (0.5: the middle; it moves every frame and core/froxel_history.comp
// averages the frames) (lib/froxel_slices.glsl, out to max_distance), with march.comp's terms (light_shafts/medium.glsl);
// layer k holds the sums from the camera to slice boundary k, which froxel_apply.comp reads per pixel:
//   the haze alone: (L, T) = (sum sigma p(cos) E exp(-tau_sun - sigma s) ds, exp(-sigma d_k));
//   SHAFT_AERIAL: rgb = the air's sunlight lost in cloud shadow, sum T_air E_sun (s_ray p_R + s_mie p_M)
//     (1 - V) f_fog ds (f_fog = 1 without a fog);
//   SHAFT_FOG: a = the fog's in-scatter share lost in cloud shadow, sum [f(d_k-1) - f(d_k)] (1 - V) T_air
//     (T_air = 1 without the aerial perspective). The fog's factor along the column depends on its
//     direction only: a heterogeneous fog (its turbulence taken at each pixel's end point) marches per texel.
// float64 twin: plugins/light_shafts/reference.py froxel_shafts.
#include "light_shafts/medium.glsl"
#include "lib/froxel_slices.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) writeonly uniform image3D shaft_volume;
uniform float froxel_knee;     // m: slices are nearly even inside it, logarithmic beyond
uniform int froxel_jittered;   // 1: the samples move with the frame (lib/froxel_slices.glsl froxel_jitter); 0: the middles

void main() {
    ivec3 size = imageSize(shaft_volume);
    ivec2 c = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(c, size.xy))) return;
    vec3 dir = view_ray_dir((vec2(c) + 0.5) / vec2(size.xy), view_basis);
    float nu = dot(dir, sun_dir);
    int slices = size.z - 1;
#if SHAFT_FOG || SHAFT_AERIAL
    vec4 sums = vec4(0.0);
#else
    vec4 sums = vec4(0.0, 0.0, 0.0, 1.0);
    vec3 lit = irradiance * (scattering * phase2(nu, lobes));
#endif
#if SHAFT_FOG
    vec3 end = camera_pos + dir * max_distance;       // the fog's factor toward it (its direction alone)
    float f0 = fog_factor(0.0, end, camera_pos);
#endif
#if SHAFT_AERIAL
    float r = atm_clamp_radius(view_r);
    float pr = atm_rayleigh_phase(nu), pm = atm_hg_phase(atm_g, nu);
#endif
    imageStore(shaft_volume, ivec3(c, 0), sums);
    float d0 = 0.0, jitter = froxel_jitter(frame_index, froxel_jittered != 0);
    for (int z = 1; z <= slices; ++z) {
        float d1 = froxel_distance(float(z) / float(slices), max_distance, froxel_knee);
        float s = mix(d0, d1, jitter), ds = d1 - d0;
        float tau = shaft_sun_tau(camera_pos + dir * s);
        float shade = 1.0 - exp(-tau);          // the share of the sunlight the clouds take
#if SHAFT_FOG
        float f1 = fog_factor(d1, end, camera_pos);
        float air = 1.0;
#if SHAFT_AERIAL
        air = shaft_air(r, dir, nu, s);
#endif
        sums.a += (f0 - f1) * shade * air;
        f0 = f1;
#endif
#if SHAFT_AERIAL
        float fogged = 1.0;
#if SHAFT_FOG
        fogged = fog_factor(s, end, camera_pos);
#endif
        if (shade > 0.0)
            sums.rgb += shaft_air_light(r, dir, nu, s, pr, pm) * (shade * fogged * ds) * atm_sun;
#endif
#if !(SHAFT_FOG || SHAFT_AERIAL)
        sums.rgb += lit * (exp(-tau - scattering * s) * ds);
        sums.a = exp(-scattering * d1);
#endif
        imageStore(shaft_volume, ivec3(c, z), sums);
        d0 = d1;
    }
}
