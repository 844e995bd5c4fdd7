// The fog over a pixel (fog/fog.frag draws it, fog/fog.comp composites it in place): fog/over.glsl.
// FOG_FROM_DEPTH 1: distance and position from the scene depth and the camera (lib/view_ray.glsl);
// 0 (apply_fog): from a distance texture (+inf = sky) and a world-position texture.
// FOG_CLOUDS 1: "cloud_distance" (premultiplied (a·d, a), atmos/composition.py) fogs the clouds by
// their own distance: f = a f(d_cloud) + (1 - a) f(d_behind). FOG_SKY_COLOR 1: the fog colour is
// fog_color × the sky's horizon radiance in the ray's azimuth (plugins/fog/sky_color.py). LOCAL_MEDIA 1:
// the same onto the media targets (lib/media_out.glsl, lib/media_image.glsl).
// view_basis, camera_pos, near, far: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#include "fog/over.glsl"
#if FOG_CLOUDS
#include "lib/cloud_distance.glsl"
layout(binding = 2) uniform sampler2D cloud_distance;
#endif
#if FOG_FROM_DEPTH
layout(binding = 0) uniform sampler2D scene_depth;
#else
layout(binding = 0) uniform sampler2D fog_distance;
layout(binding = 1) uniform sampler2D fog_position;
uniform float fog_far;       // distance sky pixels are fogged at (may be +inf)
layout(binding = 7) uniform sampler2D fog_direction;   // unit view directions (clouds, sky colour)
uniform vec3 fog_camera;     // the cloud's world point is fog_camera + direction × its distance
#endif

vec4 fog_medium(ivec2 px, vec2 uv) {
#if FOG_FROM_DEPTH
    vec3 ray = view_ray(uv, view_basis);
    float d;
    vec3 world;
    bool sky = fog_ray_end(texelFetch(scene_depth, px, 0).r, ray, d, world);   // exact texel: no blend across edges
    vec3 dir = normalize(ray);
    vec3 eye = camera_pos;
#else
    float d = texelFetch(fog_distance, px, 0).r;
    vec3 world = texelFetch(fog_position, px, 0).xyz;
    bool sky = d > 3.0e38;
    if (sky) d = fog_far;
    vec3 dir = texelFetch(fog_direction, px, 0).xyz;
    vec3 eye = fog_camera;
#endif
#if FOG_CLOUDS
    vec2 cloud = cloud_cover_distance(texelFetch(cloud_distance, px, 0).rg);
#else
    vec2 cloud = vec2(0.0);
#endif
    return fog_over(d, world, dir, eye, sky, cloud);
}
