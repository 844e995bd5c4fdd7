#version 430
// The simulation's cover for the far field (float64 reference: atmos/plugins/clouds/far_field/reference.py
// volume_cover, column_quantiles): Σ w·[sum > threshold] / Σ w over the columns of mix(A, B, t) (A at
// c + a_shift, empty past its edge), w the volume's edge weight at the column's centre; and the
// w-weighted quantiles 0, 1/32, ..., 1 of the column sums (cells), from a histogram of BINS bins over
// [0, max_sum] (empty columns counted apart: quantiles inside their share are exactly 0), interpolated
// linearly inside a bin; and `transitions`, the cover's changes per cell along a line: the fraction
// (weighted by the lesser edge weight of the two) of neighbouring column pairs along x and z of which
// one is covered and the other not (reference: volume_transitions). One work group of 256.
// PROFILE 1 (when the ray march draws the far field): then the columns' vertical shape by rank
// (reference: column_profile): each covered column (sum above
// EMPTY) falls in the rank interval k (0..31) of the quantiles just measured its sum lies in, and adds
// w x its density at the P = imageSize(column_profile).y height samples (cell centres when P = the
// layer's height in cells, nearest cell otherwise) to interval k's profile. Texel (k, j) gets
//   R = profile_j / sum_i profile_i x P / ny   (density per unit column sum in cells at height sample j)
//   G = (sum_{i > j} profile_i + profile_j / 2) / sum_i profile_i   (the share of the column above it)
// an interval without columns takes the nearest one's (above first), and with no covered column at all
// R is uniform. The far field's density at rank r and height fraction h is then
// far_quantile(r) x R(r, h) (clouds/raymarch/far.glsl): the volume's own vertical shape per thickness.
#ifndef PROFILE
#define PROFILE 0
#endif
#include "clouds/far_field/columns.glsl"
layout(local_size_x = 256) in;
#if PROFILE
layout(rg32f, binding = 0) writeonly uniform image2D column_profile;   // (32 intervals, P heights)
#endif
layout(std430, binding = 0) writeonly buffer Cover { float cover; float column_quantiles[33]; float transitions; };
uniform float threshold;
uniform float max_sum;         // the histogram's range: the layer's height in cells
const int BINS = 256;
const int MAX_HEIGHTS = 64;         // most height samples P (FarFieldLayer sizes the image)
const float DENSITY_UNIT = 16.0;    // fixed point of density x weight units (density clamped to 1)
shared vec2 partial[256];
shared vec2 edges[256];             // (weight of neighbour pairs that differ in cover, weight of pairs)
shared uint hist[BINS + 1];         // [0]: empty columns, [1 + i]: bin i
shared float quantile[33];
#if PROFILE
shared uint profile[INTERVALS * MAX_HEIGHTS];
shared float total[INTERVALS];
#endif

void main() {
    ivec2 n = textureSize(sums_b, 0).xy;
    uint i = gl_LocalInvocationIndex;
    hist[i + 1u] = 0u;
    if (i == 0u) hist[0] = 0u;
#if PROFILE
    for (uint k = i; k < uint(INTERVALS * MAX_HEIGHTS); k += 256u) profile[k] = 0u;
#endif
    barrier();
    vec2 acc = vec2(0.0), pairs = vec2(0.0);
    float bin_width = max(max_sum, 1e-6) / float(BINS);
    for (int c = int(i); c < n.x * n.y; c += 256) {
        ivec2 p = ivec2(c % n.x, c / n.x);
        float s = column_sum(p, n);
        float w = cloud_edge_weight((vec2(p) + 0.5) / vec2(n), edge_fade);
        acc += vec2(s > threshold ? w : 0.0, w);
        // the cover's transitions: pairs with the next column along x and along z, weighted by the lesser weight
        for (int axis = 0; axis < 2; ++axis) {
            ivec2 q = p + (axis == 0 ? ivec2(1, 0) : ivec2(0, 1));
            if (q.x >= n.x || q.y >= n.y) continue;
            float wp = min(w, cloud_edge_weight((vec2(q) + 0.5) / vec2(n), edge_fade));
            pairs += vec2((s > threshold) != (column_sum(q, n) > threshold) ? wp : 0.0, wp);
        }
        uint units = uint(round(w * WEIGHT_UNIT));
        if (units > 0u) {
            int bin = s > EMPTY ? 1 + clamp(int(s / bin_width), 0, BINS - 1) : 0;
            atomicAdd(hist[bin], units);
        }
    }
    partial[i] = acc;
    edges[i] = pairs;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (i < stride) { partial[i] += partial[i + stride]; edges[i] += edges[i + stride]; }
        barrier();
    }
    if (i == 0u) {
        cover = partial[0].x / max(partial[0].y, 1e-30);
        transitions = edges[0].x / max(edges[0].y, 1e-30);
        float total = 0.0;
        for (int b = 0; b <= BINS; ++b) total += float(hist[b]);
        float below = float(hist[0]);      // weight at or below the current bin's start
        int b = 0;                         // bins 0..b-1 (of 1..BINS) lie below `below`
        for (int k = 0; k <= 32; ++k) {
            float target = total * float(k) / 32.0;
            if (total <= 0.0 || target <= float(hist[0])) { column_quantiles[k] = quantile[k] = 0.0; continue; }
            while (b < BINS - 1 && below + float(hist[b + 1]) < target) { below += float(hist[b + 1]); ++b; }
            float h = float(hist[b + 1]);
            float f = h > 0.0 ? clamp((target - below) / h, 0.0, 1.0) : 1.0;
            column_quantiles[k] = quantile[k] = (float(b) + f) * bin_width;
        }
    }
#if PROFILE
    barrier();
    // the vertical profiles of the covered columns, by the rank interval of their sum
    ivec3 size = textureSize(density_b, 0);
    int heights = min(imageSize(column_profile).y, MAX_HEIGHTS);
    for (int c = int(i); c < n.x * n.y; c += 256) {
        ivec2 p = ivec2(c % n.x, c / n.x);
        float s = column_sum(p, n);
        uint units = column_units(p, n);
        if (s <= EMPTY || units == 0u) continue;
        int k = rank_interval(quantile, s);
        for (int j = 0; j < heights; ++j) {
            float d = column_density(ivec3(p.x, sample_row(j, heights, size.y), p.y), size);
            atomicAdd(profile[k * MAX_HEIGHTS + j], uint(round(d * DENSITY_UNIT * float(units))));
        }
    }
    barrier();
    if (i < uint(INTERVALS)) {
        float sum = 0.0;
        for (int j = 0; j < heights; ++j) sum += float(profile[int(i) * MAX_HEIGHTS + j]);
        total[i] = sum;
    }
    barrier();
    if (i < uint(INTERVALS)) {
        int k = -1;                         // the nearest interval with columns, above first
        for (int d = 0; d < INTERVALS && k < 0; ++d) {
            if (int(i) + d < INTERVALS && total[int(i) + d] > 0.0) k = int(i) + d;
            else if (int(i) - d >= 0 && total[int(i) - d] > 0.0) k = int(i) - d;
        }
        float above = k >= 0 ? total[k] : 0.0;
        for (int j = 0; j < heights; ++j) {
            vec2 rg;
            if (k < 0) {
                rg = vec2(1.0 / float(size.y), 1.0 - (float(j) + 0.5) / float(heights));
            } else {
                float v = float(profile[k * MAX_HEIGHTS + j]);
                above -= v;
                rg = vec2(v * float(heights) / (total[k] * float(size.y)), (above + 0.5 * v) / total[k]);
            }
            imageStore(column_profile, ivec2(int(i), j), vec4(rg, 0.0, 0.0));
        }
    }
#endif
}
