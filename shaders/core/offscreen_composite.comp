#version 430
// The low-resolution layer upsampled onto the frame, one compute invocation per pixel, depth-aware
// (lib/upsample.glsl: bilinear inside surfaces, the texel nearest in depth at geometry edges), and
// composited in place: clouds (premultiplied rgb, coverage a) over the colour, rgb and alpha both
// = layer + (1 - a) · colour; COMPOSITE_MEDIUM 1: a medium's (light, transmittance), rgb = L + T · rgb,
// alpha kept. COMPOSITE_DISTANCE 1: their premultiplied distance (a·distance, a) (atmos/composition.py)
// over "cloud_distance" with the same weights: rg = layer + (1 - a) · rg; 2 (its first writer, no clear
// before): stored.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D clouds;
layout(binding = 1) uniform sampler2D cloud_depth;   // the farthest scene depth of each block
layout(binding = 2) uniform sampler2D scene_depth;
layout(binding = 0, rgba16f) uniform image2D color_image;
#if COMPOSITE_DISTANCE
layout(binding = 3) uniform sampler2D cloud_distance;  // the low-res distance
#if COMPOSITE_DISTANCE == 2
layout(binding = 1, rg32f) writeonly uniform image2D distance_image;
#else
layout(binding = 1, rg32f) uniform image2D distance_image;
#endif
#endif
uniform int factor;
uniform vec2 inv_near_far;   // (1/near, 1/far): 1/view depth is linear in window depth
uniform float edge;          // relative view-depth difference that makes an edge
uniform vec2 sample_offset;  // texel (i, j) holds the frame's pixel (i, j) * factor + sample_offset

#include "lib/upsample.glsl"
#include "lib/over.glsl"

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, imageSize(color_image)))) return;
    vec2 p = (vec2(px) - sample_offset) / float(factor);   // low-res texel centres at integers
    float w = upsample_inv_depth(texelFetch(scene_depth, px, 0).r, inv_near_far);
    ivec2 taps[4];
    float weights[4];
    upsample_taps(cloud_depth, textureSize(clouds, 0) - 1, p, w, inv_near_far, edge, taps, weights);
    vec4 sum = vec4(0.0);
    for (int k = 0; k < 4; ++k) sum += weights[k] * texelFetch(clouds, taps[k], 0);
    vec4 c = imageLoad(color_image, px);
#if COMPOSITE_MEDIUM
    imageStore(color_image, px, vec4(sum.rgb + sum.a * c.rgb, c.a));
#else
    imageStore(color_image, px, over(sum, c));
#endif
#if COMPOSITE_DISTANCE
    vec2 dist = vec2(0.0);
    for (int k = 0; k < 4; ++k) dist += weights[k] * texelFetch(cloud_distance, taps[k], 0).rg;
#if COMPOSITE_DISTANCE == 2
    imageStore(distance_image, px, vec4(dist, 0.0, 0.0));
#else
    imageStore(distance_image, px, vec4(over(dist, imageLoad(distance_image, px).rg), 0.0, 0.0));
#endif
#endif
}
