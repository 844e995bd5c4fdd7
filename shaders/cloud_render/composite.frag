#version 430
// The low-resolution clouds (premultiplied rgb, coverage a) upsampled onto the frame, blended
// ONE, ONE_MINUS_SRC_ALPHA. Bilinear where the four nearest low-res texels saw this pixel's depth;
// at a geometry edge, the texel whose depth is nearest this pixel's (nearest-depth upsampling), so
// clouds neither bleed over near geometry nor leave gaps beside it.
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

float inv_depth(float d) { return mix(inv_near_far.x, inv_near_far.y, d); }

void main() {
    ivec2 last = textureSize(clouds, 0) - 1;
    vec2 p = (gl_FragCoord.xy - 0.5 - sample_offset) / float(factor);   // low-res texel centres at integers
    ivec2 p0 = ivec2(floor(p));
    vec2 f = p - vec2(p0);
    float w = inv_depth(texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r);
    vec4 sum = vec4(0.0);
    vec4 nearest = vec4(0.0);
    vec2 dsum = vec2(0.0), dnearest = vec2(0.0);
    float best = 1e30;
    bool is_edge = false;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 q = clamp(p0 + o, ivec2(0), last);
        vec4 c = texelFetch(clouds, q, 0);
        float wq = inv_depth(texelFetch(cloud_depth, q, 0).r);
        float rel = abs(w - wq) / max(min(w, wq), 1e-30);    // |z - zq| / min(z, zq)
        vec2 b = mix(1.0 - f, f, vec2(o));
        vec2 dq = texelFetch(cloud_distance, q, 0).rg;
        sum += b.x * b.y * c;
        dsum += b.x * b.y * dq;
        is_edge = is_edge || rel > edge;
        if (rel < best) { best = rel; nearest = c; dnearest = dq; }
    }
    frag = is_edge ? nearest : sum;
    vec2 dist = is_edge ? dnearest : dsum;
    frag_distance = vec4(dist, 0.0, dist.y);   // blends by its own alpha onto the cleared target
}
