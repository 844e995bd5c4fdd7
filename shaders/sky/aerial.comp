#version 430
// Aerial perspective of the physical sky (SkySettings.aerial_perspective): the air between the camera
// and what each pixel shows scatters sunlight toward the camera and dims what lies behind it, marched
// per pixel through the same atmosphere and LUTs as the sky (sky/atmosphere.glsl atm_aerial, AERIAL_STEPS
// segments), one compute invocation per pixel composited in place (lib/media_image.glsl): rgb = in-scattered
// light, T = the mean of the RGB transmittance (Hillaire's grey transmittance), so the colour becomes
// L + T·C. Sky pixels
// (depth 1) already hold the whole ray: left alone. AERIAL_CLOUDS 1: "cloud_distance" (premultiplied
// (a·d, a), atmos/composition.py) gives the clouds their own distance: a·AP(d_cloud) + (1 - a)·AP(d).
// AERIAL_VOLUME 1 (SkySettings.aerial_froxels): AP(d) is rebuilt from the froxel volume
// (sky/aerial_volume.comp: the air's colour and extinction, read trilinearly at (uv, the slice of d,
// sky/aerial_slices.glsl)); a ray longer than its range (far clouds), or whose froxels straddle the
// horizon, marches itself. float64 reference: plugins/sky/atmosphere.py aerial_perspective.
// AERIAL_MEDIA 1: a local medium (the fog) has blended its (L_l, T_l) over the colour already, C1 =
// C T_l + L_l, and left them in "media_light"/"media_transmittance" (atmos/composition.py): the air and
// it mixed along the ray give C T_l T_a + media_mix(air, local), i.e. media_mix - T_a L_l blended over C1.
// view_basis, near, far, sun_dir: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/media_image.glsl"
vec2 pixel_uv;                 // the pixel's uv (main sets it)
layout(binding = 0) uniform sampler2D scene_depth;
#if AERIAL_CLOUDS
#include "lib/cloud_distance.glsl"
layout(binding = 2) uniform sampler2D cloud_distance;
#endif
uniform float view_r;          // the camera's radius from the planet's centre
#include "lib/view_ray.glsl"
#include "sky/atmosphere.glsl"

vec4 aerial(vec3 dir, float distance) {
    vec3 transmittance;
    vec3 light = atm_aerial(view_r, dir.y, sun_dir.y, dot(dir, sun_dir), distance, AERIAL_STEPS, transmittance);
    return vec4(light, dot(transmittance, vec3(1.0 / 3.0)));
}
#if AERIAL_MEDIA
#include "lib/media_mix.glsl"
layout(binding = 4) uniform sampler2D media_light;
layout(binding = 5) uniform sampler2D media_transmittance;
#endif
#if AERIAL_VOLUME
#include "sky/aerial_slices.glsl"
layout(binding = 3) uniform sampler3D aerial_volume;
uniform float aerial_range;    // m: the volume's last slice (plugins/sky/aerial.py volume_range)
#endif

#if AERIAL_VOLUME
// Whether the four froxel columns the pixel reads from all end on the ground, or all leave the air
// through its top: across the horizon their air differs (a ray into the thin air above it, one down
// through the densest), and the pixels there march their own rays.
bool froxels_agree() {
    vec2 n = vec2(textureSize(aerial_volume, 0).xy);
    vec2 c0 = (floor(pixel_uv * n - 0.5) + 0.5) / n, c1 = c0 + 1.0 / n;
    float r = atm_clamp_radius(view_r);
    bool g = atm_hits_ground(r, view_ray_dir(c0, view_basis).y);
    return g == atm_hits_ground(r, view_ray_dir(vec2(c1.x, c0.y), view_basis).y)
        && g == atm_hits_ground(r, view_ray_dir(vec2(c0.x, c1.y), view_basis).y)
        && g == atm_hits_ground(r, view_ray_dir(c1, view_basis).y);
}
#endif

// The aerial perspective of the pixel's ray out to `distance`.
vec4 aerial_at(vec3 dir, float distance) {
#if AERIAL_VOLUME
    if (distance <= aerial_range && froxels_agree()) {  // the air's colour and extinction (aerial_volume.comp)
        float w = aerial_slice_w(distance, aerial_range), first = 0.5 / float(textureSize(aerial_volume, 0).z);
        vec4 air = textureLod(aerial_volume, vec3(pixel_uv, max(w, first)), 0.0);
        float T = exp(-air.a * max(distance, 0.0));
        return vec4(air.rgb * (1.0 - T), T);
    }
#endif
    return aerial(dir, distance);
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(px, size))) return;
    pixel_uv = (vec2(px) + 0.5) / vec2(size);
    float z = texelFetch(scene_depth, px, 0).r;
    vec3 ray = view_ray(pixel_uv, view_basis);
    vec3 dir = normalize(ray);
    vec4 ap = z >= 1.0 ? vec4(0.0, 0.0, 0.0, 1.0) : aerial_at(dir, view_depth(z, near, far) * length(ray));
#if AERIAL_CLOUDS
    vec2 cloud = cloud_cover_distance(texelFetch(cloud_distance, px, 0).rg);
    if (cloud.x > 0.0) ap = cloud.x * aerial_at(dir, cloud.y) + (1.0 - cloud.x) * ap;
#endif
#if AERIAL_MEDIA
    vec4 local = vec4(texelFetch(media_light, px, 0).rgb, texelFetch(media_transmittance, px, 0).r);
    ap = vec4(media_mix(ap, local) - ap.a * local.rgb, ap.a);
#endif
    blend_medium(px, ap);
}
