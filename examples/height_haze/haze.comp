#version 430
// Exponential height haze: density(y) = density * exp(-(y - base) / scale_height) between the camera
// and the surface (or max_distance for the sky), one invocation per pixel, composited onto the colour
// in place (lib/media_image.glsl): rgb = (1 - T) * haze_color + T * rgb, the alpha kept.
#include "lib/frame.glsl"          // view_basis, camera_pos, near, far: the frame block
#include "lib/view_ray.glsl"
#include "lib/media_image.glsl"    // color_image and blend_medium
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D scene_depth;
uniform float density;        // extinction (1/m) at height base
uniform float base;
uniform float scale_height;
uniform float max_distance;   // how far the sky is hazed
uniform vec3 haze_color;

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(pixel, size))) return;
    vec2 uv = (vec2(pixel) + 0.5) / vec2(size);
    float depth = texelFetch(scene_depth, pixel, 0).r;
    float s = view_ray_distance(uv, depth, view_basis, near, far, max_distance);
    vec3 dir = view_ray_dir(uv, view_basis);
    // optical depth: integral of density(y0 + t dy) over t in [0, s]
    float k = dir.y * s / scale_height;
    float along = abs(k) < 1e-4 ? s * (1.0 - 0.5 * k) : scale_height * (1.0 - exp(-k)) / dir.y;
    float t = exp(-density * exp(-(camera_pos.y - base) / scale_height) * along);
    blend_medium(pixel, vec4((1.0 - t) * haze_color, t));
}
