// The fog over a pixel (fog/fog.frag draws it, fog/fog.comp composites it in place): f from
// fog/factor.glsl, premultiplied for the blend (ONE, SRC_ALPHA):
// rgb = (1 - f) * fog_color, a = f, so the target becomes f * C_current + (1 - f) * C_fog, eq. (1).
// FOG_FROM_DEPTH 1: distance and position from the scene depth and the camera (lib/view_ray.glsl);
// 0 (apply_fog): from a distance texture (+inf = sky) and a world-position texture.
// FOG_CLOUDS 1: "cloud_distance" (premultiplied (a·d, a), atmos/composition.py) fogs the clouds by
// their own distance: f = a f(d_cloud) + (1 - a) f(d_behind). FOG_SKY_COLOR 1: the fog colour is
// fog_color × the sky's horizon radiance in the ray's azimuth (plugins/fog/sky_color.py). LOCAL_MEDIA 1:
// the same onto the media targets (lib/media_out.glsl, lib/media_image.glsl).
// view_basis, camera_pos, near, far: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
#include "fog/factor.glsl"
uniform int fog_sky_keep;    // 1: sky pixels are left to the sky
#if FOG_CLOUDS
#include "lib/cloud_distance.glsl"
layout(binding = 2) uniform sampler2D cloud_distance;
#endif
#include "fog/color.glsl"
#if FOG_FROM_DEPTH
#include "lib/view_ray.glsl"
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
    float z = texelFetch(scene_depth, px, 0).r;   // exact texel: no blend across edges
    bool sky = z >= 1.0;
    vec3 ray = view_ray(uv, view_basis);
    float view_z = sky ? far : view_depth(z, near, far);
    vec3 world = camera_pos + ray * view_z;   // sky: the far-plane point of this pixel
    float d = view_z * length(ray);
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
#if FOG_FROM_DEPTH
    // "keep" leaves the sky above the horizon to the sky; below it (seen from the air, past the terrain)
    // is the ground's continuation: fogged as the plane y = 0 at its distance (haze to the horizon)
    if (sky && fog_sky_keep != 0 && dir.y < 0.0 && eye.y > 0.0) {
        d = eye.y / max(-dir.y, 1e-6);
        world = eye + dir * d;
        sky = false;
    }
#endif
    float f = sky && fog_sky_keep != 0 ? 1.0 : fog_factor(d, world, eye);
#if FOG_CLOUDS
    vec2 cloud = cloud_cover_distance(texelFetch(cloud_distance, px, 0).rg);
    if (cloud.x > 0.0) f = cloud.x * fog_factor(cloud.y, eye + dir * cloud.y, eye) + (1.0 - cloud.x) * f;
#endif
    return vec4(in_color(dir) * (1.0 - f), f);
}
