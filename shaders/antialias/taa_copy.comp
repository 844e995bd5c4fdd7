#version 430
// Temporal anti-aliasing's second step: the resolved frame (kept as the next frame's history) back into
// the frame's colour (plugins/antialias/temporal.py).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D resolved_in;
layout(binding = 0, rgba16f) writeonly uniform image2D color_image;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(color_image)))) return;
    imageStore(color_image, p, texelFetch(resolved_in, p, 0));
}
