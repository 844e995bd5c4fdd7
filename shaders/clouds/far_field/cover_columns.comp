#version 430
// The far field's cover measure, first of its passes (cover.comp says what it measures; float64
// reference: atmos/plugins/clouds/far_field/reference.py): many groups of 256, group g taking columns
// g, g + G, ... in blocks of 256 (G = the groups dispatched). Each group adds its columns' edge-weighted
// (covered, all) weights and (differing, all) neighbour-pair weights into a partial of its own (summed
// by cover.comp in a fixed order: the same result every run) and its histogram of the column sums
// (shared memory, then integer atomics into one buffer: exact in any order).
#include "clouds/far_field/columns.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = 2) writeonly buffer CoverPartials { vec4 partials[]; };   // (covered w, w, differing w, pair w)
layout(std430, binding = 3) buffer CoverHistogram { uint hist[]; };                // [0]: empty, [1 + i]: bin i
uniform float threshold;
uniform float max_sum;         // the histogram's range: the layer's height in cells
const int BINS = 256;
shared vec4 partial[256];
shared uint local_hist[BINS + 1];

void main() {
    ivec2 n = textureSize(sums_b, 0).xy;
    uint i = gl_LocalInvocationIndex;
    int groups = int(gl_NumWorkGroups.x), g = int(gl_WorkGroupID.x);
    local_hist[i + 1u] = 0u;
    if (i == 0u) local_hist[0] = 0u;
    barrier();
    vec4 acc = vec4(0.0);
    float bin_width = max(max_sum, 1e-6) / float(BINS);
    for (int c = g * 256 + int(i); c < n.x * n.y; c += groups * 256) {
        ivec2 p = ivec2(c % n.x, c / n.x);
        float s = column_sum(p, n);
        float w = cloud_edge_weight((vec2(p) + 0.5) / vec2(n), edge_fade);
        acc.xy += vec2(s > threshold ? w : 0.0, w);
        // the cover's transitions: pairs with the next column along x and along z, weighted by the lesser weight
        for (int axis = 0; axis < 2; ++axis) {
            ivec2 q = p + (axis == 0 ? ivec2(1, 0) : ivec2(0, 1));
            if (q.x >= n.x || q.y >= n.y) continue;
            float wp = min(w, cloud_edge_weight((vec2(q) + 0.5) / vec2(n), edge_fade));
            acc.zw += vec2((s > threshold) != (column_sum(q, n) > threshold) ? wp : 0.0, wp);
        }
        uint units = uint(round(w * WEIGHT_UNIT));
        if (units > 0u) {
            int bin = s > EMPTY ? 1 + clamp(int(s / bin_width), 0, BINS - 1) : 0;
            atomicAdd(local_hist[bin], units);
        }
    }
    partial[i] = acc;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (i < stride) partial[i] += partial[i + stride];
        barrier();
    }
    if (i == 0u) partials[g] = partial[0];
    if (local_hist[i + 1u] > 0u) atomicAdd(hist[i + 1u], local_hist[i + 1u]);
    if (i == 0u && local_hist[0] > 0u) atomicAdd(hist[0], local_hist[0]);
}
