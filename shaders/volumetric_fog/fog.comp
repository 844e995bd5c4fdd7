#version 430
// Volumetric FBM fog over the scene, stopped at scene depth, one invocation per pixel: the march
// (volumetric_fog/medium.glsl) composited onto the colour in place (lib/media_image.glsl); the camera is
// the frame block's (lib/frame.glsl).
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
#include "lib/view_ray.glsl"
#include "volumetric_fog/medium.glsl"
#include "lib/media_image.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D scene_depth;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(pixel, size))) return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(size);
    vec3 dir = view_ray_dir(uv, view_basis);
    float dist = view_ray_distance(uv, texelFetch(scene_depth, pixel, 0).r, view_basis, near, far, 1e30);
    blend_medium(pixel, fog_march(camera_pos, dir, dist));
}
