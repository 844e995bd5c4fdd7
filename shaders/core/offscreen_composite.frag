#version 430
// The low-resolution clouds (premultiplied rgb, coverage a) upsampled onto the frame, blended
// ONE, ONE_MINUS_SRC_ALPHA, depth-aware (lib/upsample.glsl: bilinear inside surfaces, the
// texel nearest in depth at geometry edges).
layout(binding = 0) uniform sampler2D clouds;
layout(binding = 1) uniform sampler2D cloud_depth;   // the farthest scene depth of each block
layout(binding = 2) uniform sampler2D scene_depth;
layout(binding = 3) uniform sampler2D cloud_distance; // premultiplied (a·distance, a) (atmos/composition.py); used only
                                                      // when "cloud_distance" is attachment 1
uniform int factor;
uniform vec2 inv_near_far;   // (1/near, 1/far): 1/view depth is linear in window depth
uniform float edge;          // relative view-depth difference that makes an edge
uniform vec2 sample_offset;  // texel (i, j) holds the frame's pixel (i, j) * factor + sample_offset
out vec4 frag;
layout(location = 1) out vec4 frag_distance;

#include "lib/upsample.glsl"

void main() {
    vec2 p = (gl_FragCoord.xy - 0.5 - sample_offset) / float(factor);   // low-res texel centres at integers
    float w = upsample_inv_depth(texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r, inv_near_far);
    ivec2 taps[4];
    float weights[4];
    upsample_taps(cloud_depth, textureSize(clouds, 0) - 1, p, w, inv_near_far, edge, taps, weights);
    vec4 sum = vec4(0.0);
    vec2 dist = vec2(0.0);
    for (int k = 0; k < 4; ++k) {
        sum += weights[k] * texelFetch(clouds, taps[k], 0);
        dist += weights[k] * texelFetch(cloud_distance, taps[k], 0).rg;
    }
    frag = sum;
    frag_distance = vec4(dist, 0.0, dist.y);   // blends by its own alpha onto the cleared target
}
