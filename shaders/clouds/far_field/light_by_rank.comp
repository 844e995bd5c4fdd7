#version 430
// The volume's light by rank, for the far fields (float64 reference: atmos/plugins/clouds/far_field/
// reference.py light_by_rank). Each covered column (sum above EMPTY, edge weight w > 0) falls in the rank
// interval k of the quantiles cover.comp measured (its Cover buffer, read here). At its P height samples
// (sample_row) it takes the density-weighted mean of values, each sample weighted once more by its
// vertical transmittance exp(-tau) to the column's top (seen from above) or to its base (seen from
// below; tau: column_tau x w x the sampled densities, half its own sample's); interval k's result is the
// mean of its columns' means weighted by w:
//   sun_by_rank (k, v):   the octaves' transmittances (lib/octaves.glsl) of T (the sun transmittance of the
//                         shading volume, nearest texel; 1 without one), v = 0 seen from above, 1 from
//                         below: those (volume.glsl octave_weights_of) of the volume's columns of that
//                         rank, which the 2D far field (far.comp) lights its columns with;
//   sun_profile (k, q):  per height bin q of Q (sample j in bin j Q / P) the columns' density-weighted
//                         mean octave transmittances there (no transmittance weight), which the ray
//                         march's volumetric far field (clouds/raymarch/far.glsl) lights its density with;
//   height_by_rank (k, v): the height fraction (0 base, 1 top) of the same samples, weighted as sun_by_rank's:
//                         where the light of the columns seen from above (v = 0) or below (1) comes from,
//                         at which the 2D far field takes the sun's colour (volume.glsl sun_source_at);
//   thickness (k):       the clouds' height as a fraction of the layer: per column sqrt(12 var + 1/P^2) of
//                         its density's height (var in layer fractions; a uniform slab's thickness), mean
//                         over the interval's columns weighted by w: how high the 2D far field's clouds
//                         stand when seen at a slant (far.comp slant_rank);
// and with FIELD (the sets carry a diffusion field, plugins/clouds/light/diffusion.py):
//   field_column (k, v):  the field's (phi, F) likewise (nearest field cell);
//   field_profile (k, q): likewise the field's mean (phi, F) per height bin, for the same.
// A bin without density takes its interval's mean from above; an interval without columns the nearest
// one's (above first); none at all: T = 1, the field 0. phi is clamped to [0, FIELD_MAX], |F| to phi.
// Two dispatches (RankLight.measure): STAGE 0, one invocation per column, sums each work group's columns
// in shared memory and adds them to the Sums buffer; STAGE 1, one work group, takes the means, writes
// the images and clears Sums for the next frame. Sums in fixed point (`unit`, sized so that no uint sum
// overflows).
#ifndef FIELD
#define FIELD 0
#endif
#ifndef STAGE
#define STAGE 0
#endif
#include "clouds/far_field/columns.glsl"
#include "lib/octaves.glsl"
layout(local_size_x = 256) in;
layout(binding = 2) uniform sampler3D trans_a;       // the sun transmittance, shading scale (if has_shading)
layout(binding = 3) uniform sampler3D trans_b;
layout(binding = 16) uniform sampler3D diffusion_a;  // the diffusion field (phi, F), its own grid (FIELD)
layout(binding = 17) uniform sampler3D diffusion_b;
#if STAGE == 1
layout(rgba32f, binding = 0) writeonly uniform image2D sun_by_rank;     // (32 intervals, 2)
layout(r32f, binding = 3) writeonly uniform image2D thickness_by_rank;  // (32 intervals, 1)
layout(rgba32f, binding = 4) writeonly uniform image2D sun_profile;     // (32 intervals, Q bins)
layout(r32f, binding = 5) writeonly uniform image2D height_by_rank;     // (32 intervals, 2)
#if FIELD
layout(rgba32f, binding = 1) writeonly uniform image2D field_column;    // (32 intervals, 2)
layout(rgba32f, binding = 2) writeonly uniform image2D field_profile;   // (32 intervals, Q bins)
#endif
#endif
const float FIELD_MAX = 8.0;        // phi clamped to this (unit irradiance; a cloud's stays below 4)
const int FIELD_BINS = 16;          // most height bins Q
const int SLOT = 11;                // a column slot: weight, 4 sun transmittances, phi, F + phi (3), thickness, height
const int BIN = 9;                  // a height bin: weight, phi, F + phi (3), 4 sun transmittances
const int BINS_AT = INTERVALS * 2 * SLOT;              // the bins' sums follow the columns' (k, view) slots
const int TOTAL = BINS_AT + INTERVALS * FIELD_BINS * BIN;
layout(std430, binding = 0) readonly buffer Cover { float cover; float column_quantiles[33]; };
layout(std430, binding = 1) coherent buffer Sums { uint sums[TOTAL]; };   // zero between frames
uniform int heights;           // P: height samples per column
uniform int bins;              // Q: height bins of the profiles
uniform int has_shading;       // 0: T = 1
uniform float attenuation;     // the octaves' a (CloudLightSettings.ms_attenuation)
uniform float column_tau;      // sigma_t x cell height: optical depth of a cell of density 1, vertically
shared uint local[TOTAL];

// The fixed point: a column adds at most WEIGHT_UNIT x unit x 2 FIELD_MAX to a sum, and every column may
// fall in one interval (a uniform deck): no uint sum overflows.
float fixed_unit(ivec2 n) {
    return min(1024.0, 4.0e9 / (2.0 * FIELD_MAX * WEIGHT_UNIT * float(n.x * n.y)));
}

#if STAGE == 0
// mix(A, B, t) of `a`, `b` at density cell c's centre (n: the density's size), each set's nearest texel
// (A at c + a_shift), the index clamped to the grid like the renderers' clamp-to-edge sampling.
#define NEAREST(a, b, c, n) mix(texelFetch(a, nearest(c + ivec3(a_shift.x, 0, a_shift.y), n, textureSize(a, 0)), 0), \
                                texelFetch(b, nearest(c, n, textureSize(b, 0)), 0), t)
ivec3 nearest(ivec3 c, ivec3 n, ivec3 m) {
    return clamp(ivec3((vec3(c) + 0.5) / vec3(n) * vec3(m)), ivec3(0), m - 1);
}

// Column p's means into the work group's sums (its rank interval k, edge weight units).
void add_column(ivec2 p, ivec2 n, int k, uint units, float unit) {
    ivec3 size = textureSize(density_b, 0);
    float w = float(units) / WEIGHT_UNIT, sample_tau = column_tau * w * float(size.y) / float(heights);
    float total = 0.0, below = 0.0;              // the column's optical depth, and below the sample
    vec3 moments = vec3(0.0);                    // the density's sum, and its first two height moments
    for (int j = 0; j < heights; ++j)
        total += sample_tau * column_density(ivec3(p.x, sample_row(j, heights, size.y), p.y), size);
    float weight[2] = float[2](0.0, 0.0);        // the column's sums seen from above, from below
    float height[2] = float[2](0.0, 0.0);
    vec4 sun[2] = vec4[2](vec4(0.0), vec4(0.0)), field[2] = vec4[2](vec4(0.0), vec4(0.0));
    for (int b = 0; b < bins; ++b) {             // bin b holds the samples j with j bins / heights = b
        float bin_weight = 0.0;
        vec4 bin_field = vec4(0.0), bin_sun = vec4(0.0);
        for (int j = (b * heights + bins - 1) / bins; j < ((b + 1) * heights + bins - 1) / bins; ++j) {
            ivec3 cell = ivec3(p.x, sample_row(j, heights, size.y), p.y);
            float d = column_density(cell, size), tau = sample_tau * d;
            below += tau;
            if (d <= 0.0) continue;
            float y = (float(cell.y) + 0.5) / float(size.y);
            moments += d * vec3(1.0, y, y * y);
            float T = has_shading == 0 ? 1.0 : clamp(NEAREST(trans_a, trans_b, cell, size).r, 0.0, 1.0);
            vec4 Ta = octave_transmittances(T, attenuation);
#if FIELD
            vec4 f = NEAREST(diffusion_a, diffusion_b, cell, size);
            float phi = clamp(f.x, 0.0, FIELD_MAX);
            vec4 v = vec4(phi, clamp(f.yzw, -phi, phi) + phi);      // F + phi >= 0: unsigned sums
#else
            vec4 v = vec4(0.0);
#endif
            bin_weight += d;
            bin_field += d * v;
            bin_sun += d * Ta;
            float seen[2] = float[2](exp(-(total - below + 0.5 * tau)), exp(-(below - 0.5 * tau)));
            for (int view = 0; view < 2; ++view) {
                weight[view] += d * seen[view];
                height[view] += d * seen[view] * y;
                sun[view] += d * seen[view] * Ta;
                field[view] += d * seen[view] * v;
            }
        }
        if (bin_weight > 0.0) {                 // the column's mean in this bin, weighted by its edge weight
            uint at = uint(BINS_AT + (k * FIELD_BINS + b) * BIN);
            atomicAdd(local[at], units);
            for (int c = 0; c < 4; ++c) {
#if FIELD
                atomicAdd(local[at + 1u + uint(c)], uint(round(float(units) * unit * bin_field[c] / bin_weight)));
#endif
                atomicAdd(local[at + 5u + uint(c)], uint(round(float(units) * unit * bin_sun[c] / bin_weight)));
            }
        }
    }
    float mean = moments.y / max(moments.x, 1e-30);
    float thickness = min(sqrt(max(12.0 * (moments.z / max(moments.x, 1e-30) - mean * mean), 0.0)
                               + 1.0 / float(heights * heights)), 1.0);
    for (int view = 0; view < 2; ++view) {      // the column's means, weighted by its edge weight
        if (!(weight[view] > 0.0)) continue;
        uint at = uint((k * 2 + view) * SLOT);
        atomicAdd(local[at], units);
        atomicAdd(local[at + 9u], uint(round(float(units) * unit * thickness)));
        atomicAdd(local[at + 10u], uint(round(float(units) * unit * height[view] / weight[view])));
        for (int c = 0; c < 4; ++c) atomicAdd(local[at + 1u + uint(c)], uint(round(float(units) * unit * sun[view][c] / weight[view])));
        for (int c = 0; c < 4; ++c) atomicAdd(local[at + 5u + uint(c)], uint(round(float(units) * unit * field[view][c] / weight[view])));
    }
}

void main() {
    ivec2 n = textureSize(sums_b, 0).xy;
    uint i = gl_LocalInvocationIndex;
    for (uint k = i; k < uint(TOTAL); k += 256u) local[k] = 0u;
    barrier();
    int c = int(gl_GlobalInvocationID.x);
    if (c < n.x * n.y) {
        ivec2 p = ivec2(c % n.x, c / n.x);
        float s = column_sum(p, n);
        uint units = column_units(p, n);
        if (s > EMPTY && units > 0u) {
            float q[33];
            for (int k = 0; k < 33; ++k) q[k] = column_quantiles[k];
            add_column(p, n, rank_interval(q, s), units, fixed_unit(n));
        }
    }
    barrier();
    for (uint k = i; k < uint(TOTAL); k += 256u)
        if (local[k] != 0u) atomicAdd(sums[k], local[k]);
}
#else
// The means of slot s's channels i .. i + 3 over its weight; `none` where it holds no weight.
vec4 slot_mean(int s, int i, vec4 none, float unit) {
    float w = float(local[s * SLOT]) * unit;
    uint at = uint(s * SLOT + i);
    return w > 0.0 ? vec4(float(local[at]), float(local[at + 1u]), float(local[at + 2u]), float(local[at + 3u])) / w : none;
}

void main() {
    uint i = gl_LocalInvocationIndex;
    for (uint k = i; k < uint(TOTAL); k += 256u) {
        local[k] = sums[k];
        sums[k] = 0u;                       // for the next frame's STAGE 0
    }
    barrier();
    if (i >= uint(INTERVALS)) return;
    float unit = fixed_unit(textureSize(sums_b, 0).xy);
    int k = -1;                             // the nearest interval with columns, above first
    for (int d = 0; d < INTERVALS && k < 0; ++d) {
        if (int(i) + d < INTERVALS && local[(int(i) + d) * 2 * SLOT] > 0u) k = int(i) + d;
        else if (int(i) - d >= 0 && local[(int(i) - d) * 2 * SLOT] > 0u) k = int(i) - d;
    }
    float weight = k < 0 ? 0.0 : float(local[k * 2 * SLOT]) * unit;
    // (at most 1: the fixed point's rounding can lift the mean of a deck of whole-layer columns above it)
    imageStore(thickness_by_rank, ivec2(int(i), 0), vec4(weight > 0.0 ? min(float(local[k * 2 * SLOT + 9]) / weight, 1.0) : 1.0));
    for (int view = 0; view < 2; ++view) {
        int s = k * 2 + view;
        imageStore(sun_by_rank, ivec2(int(i), view), k < 0 ? vec4(1.0) : slot_mean(s, 1, vec4(1.0), unit));
        float w = k < 0 ? 0.0 : float(local[s * SLOT]) * unit;
        imageStore(height_by_rank, ivec2(int(i), view), vec4(w > 0.0 ? min(float(local[s * SLOT + 10]) / w, 1.0) : 0.5));
#if FIELD
        vec4 field = k < 0 ? vec4(0.0) : slot_mean(s, 5, vec4(0.0), unit);
        imageStore(field_column, ivec2(int(i), view), vec4(field.x, field.yzw - field.x));
#endif
    }
    vec4 top = k < 0 ? vec4(0.0) : slot_mean(2 * k, 5, vec4(0.0), unit);      // (phi, F + phi) seen from above
    vec4 top_sun = k < 0 ? vec4(1.0) : slot_mean(2 * k, 1, vec4(1.0), unit);
    for (int b = 0; b < bins; ++b) {
        vec4 v = top, sun = top_sun;
        if (k >= 0) {
            uint at = uint(BINS_AT + (k * FIELD_BINS + b) * BIN);
            float w = float(local[at]) * unit;
            if (w > 0.0) {
                v = vec4(float(local[at + 1u]), float(local[at + 2u]), float(local[at + 3u]), float(local[at + 4u])) / w;
                sun = vec4(float(local[at + 5u]), float(local[at + 6u]), float(local[at + 7u]), float(local[at + 8u])) / w;
            }
        }
        imageStore(sun_profile, ivec2(int(i), b), sun);
#if FIELD
        imageStore(field_profile, ivec2(int(i), b), vec4(v.x, v.yzw - v.x));
#endif
    }
}
#endif
