// The far field's cloud density as a function of world (x, z) (float64 reference:
// atmos/plugins/cloud_far_field/reference.py far_density): four scrolling tileable octaves give fbm,
// remapped from the threshold that leaves the simulation's cover (cover.comp) of the layer clouded,
//   d = remap(fbm, e, e + softness)   (four light-march channels; d.x is the point itself),
// e and the softness's scale taken per mip level (cover.py level_table: a blurred far pattern is
// thresholded by its own quantiles, so it is clouded over the same fraction, not overcast or clear).
// Shared by the far-field pass (far.frag) and the ground shadows (cloud_shadows/column.glsl with
// CLOUD_FAR_FIELD); atmos/plugins/cloud_far_field/layer.py binds it. far_field_rank(xz, lod): the
// fraction of the layer whose fbm lies below this point's (the table's inverse), for a far field that
// takes the volume's own column statistics at the same rank (column_quantiles, cover.comp: the ray
// march's volumetric far field, cloud_raymarch/far.glsl).
#include "sky_layer/layer.glsl"
layout(binding = 5) uniform sampler2D octave0;
layout(binding = 6) uniform sampler2D octave1;
layout(binding = 7) uniform sampler2D octave2;
layout(binding = 8) uniform sampler2D octave3;
layout(std430, binding = 0) readonly buffer Cover { float cover; float column_quantiles[33]; };
uniform vec2 field_origin;         // a world xz near the view (the camera's)
uniform vec2 field_origin_uv;      // it in tiles, wrapped to [0, 1) (float64 on the CPU)
uniform vec2 field_offsets[4];     // drift of each octave (tiles, wrapped)
#define FIELD_LEVELS 8
uniform float field_quantiles[FIELD_LEVELS * 33]; // cover.level_table: 33 per level
uniform float field_scale[FIELD_LEVELS];          // the softness's scale per level
uniform float field_first_level;                  // the mip level of table row 0
uniform float field_tile_size;
uniform float field_softness;
uniform float field_mid_height;    // the layer's middle plane (world y)
uniform float field_optical_depth; // optical depth of a full column

float field_threshold(float c, int level) {
    float x = (1.0 - clamp(c, 0.0, 1.0)) * 32.0;
    int k = min(int(x), 31) + 33 * level;
    return mix(field_quantiles[k], field_quantiles[k + 1], x - floor(x));
}

// The fraction of level `level`'s fbm at or below f (field_threshold's inverse: binary search, linear
// between the 33 quantiles).
float field_rank(float f, int level) {
    int base = 33 * level, lo = 0, hi = 32;
    if (f <= field_quantiles[base]) return 0.0;
    if (f >= field_quantiles[base + 32]) return 1.0;
    for (int k = 0; k < 5; ++k) {           // 2^5 = 32 intervals
        int mid = (lo + hi) / 2;
        if (field_quantiles[base + mid] <= f) lo = mid; else hi = mid;
    }
    float a = field_quantiles[base + lo], b = field_quantiles[base + hi];
    return (float(lo) + (b > a ? (f - a) / (b - a) : 0.5)) / 32.0;
}

// The volume's column sum (cells) at rank r (column_quantiles, linear between the 33): what the 2D far
// field (far.frag) and the march's (cloud_raymarch/far.glsl) take at a point of rank far_field_rank.
float far_quantile(float r) {
    float x = clamp(r, 0.0, 1.0) * 32.0;
    int k = min(int(x), 31);
    return mix(column_quantiles[k], column_quantiles[k + 1], x - float(k));
}

// The four octaves' fbm at world (x, z) = xz (four light-march channels); lod: mip level.
vec4 field_fbm(vec2 xz, float lod) {
    vec2 uv = field_origin_uv + (xz - field_origin) / field_tile_size;
    return SKY_LAYER_WEIGHTS.x * textureLod(octave0, uv + field_offsets[0], lod)
         + SKY_LAYER_WEIGHTS.y * textureLod(octave1, uv + field_offsets[1], lod)
         + SKY_LAYER_WEIGHTS.z * textureLod(octave2, uv + field_offsets[2], lod)
         + SKY_LAYER_WEIGHTS.w * textureLod(octave3, uv + field_offsets[3], lod);
}

// The table row (and the share of the next) that mip level lod reads.
float field_level(float lod) {
    return clamp(lod - field_first_level, 0.0, float(FIELD_LEVELS - 1));
}

// d at world (x, z) = xz; lod: mip level.
vec4 far_field_density(vec2 xz, float lod) {
    vec4 fbm = field_fbm(xz, lod);
    float m = field_level(lod);
    int m0 = min(int(m), FIELD_LEVELS - 2);
    float t = m - float(m0);         // trilinear filtering mixes two levels: so do the thresholds
    float e = mix(field_threshold(cover, m0), field_threshold(cover, m0 + 1), t);
    float soft = field_softness * mix(field_scale[m0], field_scale[m0 + 1], t);
    return sky_layer_remap(fbm, e, e + soft);
}

// The rank (field_rank) of the point's fbm at world xz among its level's, per channel.
vec4 far_field_rank(vec2 xz, float lod) {
    vec4 fbm = field_fbm(xz, lod);
    float m = field_level(lod);
    int m0 = min(int(m), FIELD_LEVELS - 2);
    float t = m - float(m0);
    vec4 r;
    for (int k = 0; k < 4; ++k) r[k] = mix(field_rank(fbm[k], m0), field_rank(fbm[k], m0 + 1), t);
    return r;
}
