#version 430
// The light shafts from their froxel volume (light_shafts/froxels.comp), one invocation per pixel,
// composited onto the colour in place (lib/media_image.glsl). The haze alone: (L, T) read at the pixel's
// distance (the sky: max_distance), rgb = min(L, HDR_MAX) + T rgb. With a fog or the aerial perspective
// the light lost in cloud shadow is taken away, read where march.comp's weights put it: a cloud covering a
// of the pixel at its own distance d_c, the rest at the scene's (the fog's own distance for the fog),
//   rgb -= a S(d_c) + (1 - a) S(d)   (S: the volume's sums; the fog's times fog_sun_share C_fog(dir)).
// SHAFT_FOG_COMPOSITE 1 (the fog the only local medium, atmos/composition.py): this pass composites the fog
// too (fog/over.glsl, exact per pixel), then takes the shadowed share away, in one write (the fog's own
// pass culled): rgb = L_fog + f rgb - taken. SHAFT_AIR_COMPOSITE 1: likewise the air's aerial perspective
// (sky/aerial_pixel.glsl; the sky's pass culled), with the fog mixed with it along the ray as the sky's pass
// mixes them (lib/media_mix.glsl): rgb = media_mix(air, fog) + T_air f rgb - taken, no media targets.
// shafts_lit 0 (the sun down): the media alone, the volume unread.
#include "light_shafts/medium.glsl"
#include "lib/froxel_slices.glsl"
#include "lib/media_image.glsl"
#define SHAFT_COMPOSITE (SHAFT_FOG_COMPOSITE || SHAFT_AIR_COMPOSITE)
#if SHAFT_AIR_COMPOSITE
#include "sky/aerial_pixel.glsl"
#if SHAFT_FOG_COMPOSITE
#include "lib/media_mix.glsl"
#endif
#endif
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 2) uniform sampler2D scene_depth;
layout(binding = 4) uniform sampler3D shaft_volume;
uniform float froxel_knee;
#if SHAFT_COMPOSITE
uniform int shafts_lit;        // 0: no sunlit haze to shadow (the volume is not read)
#endif

vec4 sums_at(vec2 uv, float d) {
    return froxel_read(shaft_volume, uv, d, max_distance, froxel_knee);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(pixel, size))) return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(size);
    float z = texelFetch(scene_depth, pixel, 0).r;
    float d = min(view_ray_distance(uv, z, view_basis, near, far, max_distance), max_distance);
#if SHAFT_FOG || SHAFT_AERIAL
    vec3 ray = view_ray(uv, view_basis);
    vec3 dir = normalize(ray);
    vec2 cloud = cloud_cover_distance(has_cloud_distance != 0 ? texelFetch(cloud_distance, pixel, 0).rg : vec2(0.0));
    float a = cloud.x;
    vec3 taken = vec3(0.0);
#if SHAFT_COMPOSITE
    vec4 medium = vec4(0.0, 0.0, 0.0, 1.0);      // the media's (L, T) over the pixel
#if SHAFT_FOG_COMPOSITE
    float fog_d;
    vec3 fog_end;
    bool sky = fog_ray_end(z, ray, fog_d, fog_end);
    medium = fog_over(fog_d, fog_end, dir, camera_pos, sky, cloud);
#endif
#if SHAFT_AIR_COMPOSITE
    vec4 air = aerial_pixel(z, ray, uv, cloud);
#if SHAFT_FOG_COMPOSITE
    medium = vec4(media_mix(air, medium), air.a * medium.a);
#else
    medium = air;
#endif
#endif
    if (shafts_lit != 0) {
#endif
    vec4 in_cloud = a > 0.0 ? a * sums_at(uv, cloud.y) : vec4(0.0);
#if SHAFT_FOG
    float behind = shaft_fog_behind(z, d, dir, length(ray));
    taken += fog_sun_share * in_color(dir) * (in_cloud.a + (1.0 - a) * sums_at(uv, behind).a);
#endif
#if SHAFT_AERIAL
    taken += in_cloud.rgb + (1.0 - a) * sums_at(uv, d).rgb;
#endif
#if SHAFT_COMPOSITE
    }
#else
    vec4 medium = vec4(0.0, 0.0, 0.0, 1.0);
#endif
    // never more than the pixel's light: the fog's colour taken out of a kept sky of another hue could
    // leave a channel below black
    vec4 c = imageLoad(color_image, pixel);
    taken = min(taken, max(medium.rgb + medium.a * c.rgb, vec3(0.0)));
    blend_medium(pixel, vec4(medium.rgb - taken, medium.a), c);
#else
    vec4 shafts = sums_at(uv, d);
    blend_medium(pixel, vec4(min(shafts.rgb, vec3(HDR_MAX)), shafts.a));
#endif
}
