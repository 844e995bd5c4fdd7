// The fog over one ray (fog/medium.glsl for the fog's own pass, light_shafts/froxel_apply.comp where the
// shafts composite it): f from fog/factor.glsl, premultiplied for the blend (ONE, SRC_ALPHA),
// rgb = (1 - f) * in_color(dir), a = f, so the target becomes f * C_current + (1 - f) * C_fog, eq. (1).
// Clouds in front (cloud = (coverage a, distance), lib/cloud_distance.glsl; a = 0: none) are fogged by
// their own distance: f = a f(d_cloud) + (1 - a) f(d_behind).
#include "fog/factor.glsl"
#include "fog/color.glsl"
uniform int fog_sky_keep;    // 1: sky pixels are left to the sky

// The ray's end for a pixel of scene depth z (view_basis, camera_pos, near, far: the frame block): its
// distance d and point (the sky: the far plane's point); "keep" leaves the sky above the horizon to the sky,
// and below it (seen from the air, past the terrain) fogs the ground's continuation, the plane y = 0 at its
// distance (haze to the horizon). Returns whether the end is sky.
bool fog_ray_end(float z, vec3 ray, out float d, out vec3 world) {
    bool sky = z >= 1.0;
    float view_z = sky ? far : view_depth(z, near, far);
    world = camera_pos + ray * view_z;
    d = view_z * length(ray);
    vec3 dir = normalize(ray);
    if (sky && fog_sky_keep != 0 && dir.y < 0.0 && camera_pos.y > 0.0) {
        d = camera_pos.y / max(-dir.y, 1e-6);
        world = camera_pos + dir * d;
        sky = false;
    }
    return sky;
}

vec4 fog_over(float d, vec3 world, vec3 dir, vec3 eye, bool sky, vec2 cloud) {
    float f = sky && fog_sky_keep != 0 ? 1.0 : fog_factor(d, world, eye);
    if (cloud.x > 0.0) f = cloud.x * fog_factor(cloud.y, eye + dir * cloud.y, eye) + (1.0 - cloud.x) * f;
    return vec4(in_color(dir) * (1.0 - f), f);
}
