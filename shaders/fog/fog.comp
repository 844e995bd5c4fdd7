#version 430
// The fog over the scene from its depth (FOG_FROM_DEPTH 1), one invocation per pixel: fog/medium.glsl
// composited onto the colour in place (lib/media_image.glsl; the media targets too with LOCAL_MEDIA).
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/media_image.glsl"
#include "fog/medium.glsl"

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(pixel, size))) return;
    blend_medium(pixel, fog_medium(pixel, (vec2(pixel) + 0.5) / vec2(size)));
}
