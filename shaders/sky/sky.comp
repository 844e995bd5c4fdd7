#version 430
// The sky pass, one compute invocation per pixel: where nothing was drawn (depth 1) the sky along the
// pixel's view ray — analytic (sky/sky_pixel.glsl) or, SKY_PHYSICAL 1, the physical sky's sky-view LUT
// (sky/physical_pixel.glsl) — written into the colour.
#include "lib/frame.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D scene_depth;
layout(binding = 0, rgba16f) writeonly uniform image2D color_image;
#if SKY_PHYSICAL
#include "sky/physical_pixel.glsl"
#else
#include "sky/sky_pixel.glsl"
#endif

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(px, size)) || texelFetch(scene_depth, px, 0).r < 1.0) return;
    imageStore(color_image, px, sky_pixel((vec2(px) + 0.5) / vec2(size)));
}
