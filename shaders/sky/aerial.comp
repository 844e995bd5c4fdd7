#version 430
// Aerial perspective of the physical sky (SkySettings.aerial_perspective): the air between the camera
// and what each pixel shows scatters sunlight toward the camera and dims what lies behind it
// (sky/aerial_pixel.glsl: marched per pixel, or from the froxel volume with AERIAL_VOLUME 1), one compute
// invocation per pixel composited in place (lib/media_image.glsl): rgb = in-scattered light, T = the mean
// of the RGB transmittance (Hillaire's grey transmittance), so the colour becomes L + T·C. Sky pixels
// (depth 1) already hold the whole ray: left alone. AERIAL_CLOUDS 1: "cloud_distance" (premultiplied
// (a·d, a), atmos/composition.py) gives the clouds their own distance: a·AP(d_cloud) + (1 - a)·AP(d).
// AERIAL_MEDIA 1: a local medium (the fog) has blended its (L_l, T_l) over the colour already, C1 =
// C T_l + L_l, and left them in "media_light"/"media_transmittance" (atmos/composition.py): the air and
// it mixed along the ray give C T_l T_a + media_mix(air, local), i.e. media_mix - T_a L_l blended over C1.
// view_basis, near, far, sun_dir: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/media_image.glsl"
layout(binding = 0) uniform sampler2D scene_depth;
#if AERIAL_CLOUDS
#include "lib/cloud_distance.glsl"
layout(binding = 2) uniform sampler2D cloud_distance;
#endif
uniform float view_r;          // the camera's radius from the planet's centre
#include "lib/view_ray.glsl"
#include "sky/atmosphere.glsl"
#include "sky/aerial_pixel.glsl"
#if AERIAL_MEDIA
#include "lib/media_mix.glsl"
layout(binding = 4) uniform sampler2D media_light;
layout(binding = 5) uniform sampler2D media_transmittance;
#endif

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(px, size))) return;
    vec2 uv = (vec2(px) + 0.5) / vec2(size);
#if AERIAL_CLOUDS
    vec2 cloud = cloud_cover_distance(texelFetch(cloud_distance, px, 0).rg);
#else
    vec2 cloud = vec2(0.0);
#endif
    vec4 ap = aerial_pixel(texelFetch(scene_depth, px, 0).r, view_ray(uv, view_basis), uv, cloud);
#if AERIAL_MEDIA
    vec4 local = vec4(texelFetch(media_light, px, 0).rgb, texelFetch(media_transmittance, px, 0).r);
    ap = vec4(media_mix(ap, local) - ap.a * local.rgb, ap.a);
#endif
    blend_medium(px, ap);
}
