#version 430
// The simulation's cover for the far field (float64 reference: atmos/plugins/cloud_far_field/reference.py
// volume_cover, column_quantiles): Σ w·[sum > threshold] / Σ w over the columns of mix(A, B, t) (A at
// c + a_shift, empty past its edge), w the volume's edge weight at the column's centre; and the
// w-weighted quantiles 0, 1/32, ..., 1 of the column sums (cells), from a histogram of BINS bins over
// [0, max_sum] (empty columns counted apart: quantiles inside their share are exactly 0), interpolated
// linearly inside a bin. One work group of 256.
#include "clouds/edge.glsl"
layout(local_size_x = 256) in;
layout(binding = 0) uniform sampler2DArray sums_a;
layout(binding = 1) uniform sampler2DArray sums_b;
layout(std430, binding = 0) writeonly buffer Cover { float cover; float column_quantiles[33]; };
uniform float t;
uniform ivec2 a_shift;
uniform float threshold;
uniform float edge_fade;
uniform float max_sum;         // the histogram's range: the layer's height in cells
const int BINS = 256;
const float WEIGHT_UNIT = 1024.0;   // fixed point of the edge weights in the histogram
const float EMPTY = 1e-6;           // a column sum at or below this is empty
shared vec2 partial[256];
shared uint hist[BINS + 1];         // [0]: empty columns, [1 + i]: bin i

void main() {
    ivec2 n = textureSize(sums_b, 0).xy;
    uint i = gl_LocalInvocationIndex;
    hist[i + 1u] = 0u;
    if (i == 0u) hist[0] = 0u;
    barrier();
    vec2 acc = vec2(0.0);
    float bin_width = max(max_sum, 1e-6) / float(BINS);
    for (int c = int(i); c < n.x * n.y; c += 256) {
        ivec2 p = ivec2(c % n.x, c / n.x);
        ivec2 pa = p + a_shift;
        float a = any(lessThan(pa, ivec2(0))) || any(greaterThanEqual(pa, n)) ? 0.0 : texelFetch(sums_a, ivec3(pa, 0), 0).r;
        float s = mix(a, texelFetch(sums_b, ivec3(p, 0), 0).r, t);
        float w = cloud_edge_weight((vec2(p) + 0.5) / vec2(n), edge_fade);
        acc += vec2(s > threshold ? w : 0.0, w);
        uint units = uint(round(w * WEIGHT_UNIT));
        if (units > 0u) {
            int bin = s > EMPTY ? 1 + clamp(int(s / bin_width), 0, BINS - 1) : 0;
            atomicAdd(hist[bin], units);
        }
    }
    partial[i] = acc;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (i < stride) partial[i] += partial[i + stride];
        barrier();
    }
    if (i == 0u) {
        cover = partial[0].x / max(partial[0].y, 1e-30);
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
}
