// The simulation's columns as the far field's measures read them (cover.comp, light_by_rank.comp):
// mix(A, B, t) of the column sums and densities, A read at c + a_shift and empty past its edge; the
// rank interval of a column sum among the 33 quantiles; the height samples.
#include "clouds/volume/edge.glsl"
layout(binding = 0) uniform sampler2DArray sums_a;
layout(binding = 1) uniform sampler2DArray sums_b;
layout(binding = 14) uniform sampler3D density_a;   // the sets' density (units no renderer binds)
layout(binding = 15) uniform sampler3D density_b;
uniform float t;
uniform ivec2 a_shift;
uniform float edge_fade;
const float EMPTY = 1e-6;           // a column sum at or below this is empty
const int INTERVALS = 32;           // rank intervals (between the 33 quantiles)

// Column p's sum of mix(A, B, t) (A read at p + a_shift, empty past its edge).
float column_sum(ivec2 p, ivec2 n) {
    ivec2 pa = p + a_shift;
    float a = any(lessThan(pa, ivec2(0))) || any(greaterThanEqual(pa, n)) ? 0.0 : texelFetch(sums_a, ivec3(pa, 0), 0).r;
    return mix(a, texelFetch(sums_b, ivec3(p, 0), 0).r, t);
}

// Cell c's density of mix(A, B, t), clamped to [0, 1].
float column_density(ivec3 c, ivec3 n) {
    ivec3 ca = c + ivec3(a_shift.x, 0, a_shift.y);
    float a = any(lessThan(ca, ivec3(0))) || any(greaterThanEqual(ca, n)) ? 0.0 : texelFetch(density_a, ca, 0).r;
    return clamp(mix(a, texelFetch(density_b, c, 0).r, t), 0.0, 1.0);
}

// The interval k (0..INTERVALS-1) of the quantiles q with q[k] <= s < q[k + 1] (binary search).
int rank_interval(float q[33], float s) {
    int lo = 0, hi = 32;
    for (int k = 0; k < 5; ++k) {
        int mid = (lo + hi) / 2;
        if (q[mid] <= s) lo = mid; else hi = mid;
    }
    return min(lo, INTERVALS - 1);
}

// The layer's row of height sample j of `heights` (cell centres, or the nearest cell); ny: its rows.
int sample_row(int j, int heights, int ny) {
    return min(int((float(j) + 0.5) * float(ny) / float(heights)), ny - 1);
}

// The edge weight of column p of n in WEIGHT_UNIT fixed point (the measures' histogram and sums).
const float WEIGHT_UNIT = 1024.0;
uint column_units(ivec2 p, ivec2 n) {
    return uint(round(cloud_edge_weight((vec2(p) + 0.5) / vec2(n), edge_fade) * WEIGHT_UNIT));
}
