#version 430
// The covered columns' vertical profile by rank, second pass (one group): per rank interval k and height
// sample j, texel (k, j) of column_profile gets R = profile_j / sum_i profile_i x P / ny and G = the share
// of the column above it (cover.comp says what they mean); an interval without columns takes the nearest
// one's (above first), and with no covered column at all R is uniform.
layout(local_size_x = 32) in;
const int INTERVALS = 32;
const int MAX_HEIGHTS = 64;
layout(rg32f, binding = 0) writeonly uniform image2D column_profile;   // (32 intervals, P heights)
layout(std430, binding = 4) buffer CoverProfile { uint profile[]; };   // zeroed once read
uniform int heights;
uniform int layer_rows;        // the layer's height in cells (ny)
shared float total[INTERVALS];

void main() {
    uint i = gl_LocalInvocationIndex;
    ivec3 size = ivec3(0, layer_rows, 0);
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
    barrier();
    for (int j = 0; j < MAX_HEIGHTS; ++j) profile[int(i) * MAX_HEIGHTS + j] = 0u;   // zeroed for the next measure
}
