#version 430
// A depth texture as a shader's sampler reads it (texelFetch .r), copied into an r32f image: what a
// depth written by a compute pass is compared with (a readback converts 24-bit depth its own way).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D depth;
layout(binding = 0, r32f) writeonly uniform image2D fetched;

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(fetched)))) return;
    imageStore(fetched, px, vec4(texelFetch(depth, px, 0).r, 0.0, 0.0, 0.0));
}
