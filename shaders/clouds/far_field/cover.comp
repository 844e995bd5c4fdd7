#version 430
// The simulation's cover for the far field (float64 reference: atmos/plugins/clouds/far_field/reference.py
// volume_cover, column_quantiles): Σ w·[sum > threshold] / Σ w over the columns of mix(A, B, t) (A at
// c + a_shift, empty past its edge), w the volume's edge weight at the column's centre; and the
// w-weighted quantiles 0, 1/32, ..., 1 of the column sums (cells), from a histogram of BINS bins over
// [0, max_sum] (empty columns counted apart: quantiles inside their share are exactly 0), interpolated
// linearly inside a bin; and `transitions`, the cover's changes per cell along a line: the fraction
// (weighted by the lesser edge weight of the two) of neighbouring column pairs along x and z of which
// one is covered and the other not (reference: volume_transitions).
// Passes: cover_columns.comp (many groups: partial sums and the histogram), this one (one group: the
// totals and the quantiles), and with the profile (when the ray march draws the far field)
// cover_profile.comp (many groups) and cover_profile_finish.comp (one group): the columns' vertical
// shape by rank (reference: column_profile): each covered column (sum above
// EMPTY) falls in the rank interval k (0..31) of the quantiles just measured its sum lies in, and adds
// w x its density at the P = imageSize(column_profile).y height samples (cell centres when P = the
// layer's height in cells, nearest cell otherwise) to interval k's profile. Texel (k, j) gets
//   R = profile_j / sum_i profile_i x P / ny   (density per unit column sum in cells at height sample j)
//   G = (sum_{i > j} profile_i + profile_j / 2) / sum_i profile_i   (the share of the column above it)
// an interval without columns takes the nearest one's (above first), and with no covered column at all
// R is uniform. The far field's density at rank r and height fraction h is then
// far_quantile(r) x R(r, h) (clouds/raymarch/far.glsl): the volume's own vertical shape per thickness.
layout(local_size_x = 256) in;
layout(std430, binding = 0) writeonly buffer Cover { float cover; float column_quantiles[33]; float transitions; };
layout(std430, binding = 2) readonly buffer CoverPartials { vec4 partials[]; };
layout(std430, binding = 3) buffer CoverHistogram { uint hist[]; };   // zeroed once read
uniform int groups;            // partials written by cover_columns.comp
uniform float max_sum;         // the histogram's range: the layer's height in cells
const int BINS = 256;
shared vec4 partial[256];

void main() {
    uint i = gl_LocalInvocationIndex;
    vec4 acc = vec4(0.0);
    for (int g = int(i); g < groups; g += 256) acc += partials[g];
    partial[i] = acc;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (i < stride) partial[i] += partial[i + stride];
        barrier();
    }
    if (i == 0u) {
        cover = partial[0].x / max(partial[0].y, 1e-30);
        transitions = partial[0].z / max(partial[0].w, 1e-30);
        float bin_width = max(max_sum, 1e-6) / float(BINS);
        float total = 0.0;
        for (int b = 0; b <= BINS; ++b) total += float(hist[b]);
        float below = float(hist[0]);      // weight at or below the current bin's start
        int b = 0;                         // bins 0..b-1 (of 1..BINS) lie below `below`
        for (int k = 0; k <= 32; ++k) {
            float target = total * float(k) / 32.0;
            if (total <= 0.0 || target <= float(hist[0])) { column_quantiles[k] = 0.0; continue; }
            while (b < BINS - 1 && below + float(hist[b + 1]) < target) { below += float(hist[b + 1]); ++b; }
            float h = float(hist[b + 1]);
            float f = h > 0.0 ? clamp((target - below) / h, 0.0, 1.0) : 1.0;
            column_quantiles[k] = (float(b) + f) * bin_width;
        }
    }
    barrier();
    hist[i + 1u] = 0u;                 // read: zeroed for the next measure (no clear between frames)
    if (i == 0u) hist[0] = 0u;
}
