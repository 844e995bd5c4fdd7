#version 430
// The covered columns' vertical profile by rank (cover.comp's PROFILE part; reference: column_profile),
// first of two passes: many groups of 256 (columns as in cover_columns.comp), each covered column adding
// w x its density at the height samples to the rank interval its sum falls in among the quantiles
// cover.comp just measured (integer atomics in fixed point: exact in any order).
#include "clouds/far_field/columns.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Cover { float cover; float column_quantiles[33]; float transitions; };
layout(std430, binding = 4) buffer CoverProfile { uint profile[]; };     // [k * MAX_HEIGHTS + j]
uniform int heights;           // height samples P
const int MAX_HEIGHTS = 64;
const float DENSITY_UNIT = 16.0;    // fixed point of density x weight units (density clamped to 1)

void main() {
    ivec2 n = textureSize(sums_b, 0).xy;
    ivec3 size = textureSize(density_b, 0);
    float quantile[33];
    for (int k = 0; k <= 32; ++k) quantile[k] = column_quantiles[k];
    int groups = int(gl_NumWorkGroups.x), g = int(gl_WorkGroupID.x);
    for (int c = g * 256 + int(gl_LocalInvocationIndex); c < n.x * n.y; c += groups * 256) {
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
}
