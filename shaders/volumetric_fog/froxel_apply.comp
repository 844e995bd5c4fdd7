#version 430
// The volumetric fog from its froxel volume (volumetric_fog/froxels.comp), one invocation per pixel:
// (light, transmittance) read trilinearly at the pixel's uv and the slice of its scene distance (capped
// at max_distance, where the march ends), composited onto the colour in place (lib/media_image.glsl).
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#include "lib/froxel_slices.glsl"
#include "lib/media_image.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D scene_depth;
layout(binding = 1) uniform sampler3D fog_volume;
uniform float max_distance;
uniform float froxel_knee;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(pixel, size))) return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(size);
    float dist = view_ray_distance(uv, texelFetch(scene_depth, pixel, 0).r, view_basis, near, far, 1e30);
    blend_medium(pixel, froxel_read(fog_volume, uv, dist, max_distance, froxel_knee));
}
