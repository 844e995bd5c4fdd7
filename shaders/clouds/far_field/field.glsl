// The far field's cloud pattern as a function of world (x, z) (float64 reference:
// atmos/plugins/clouds/far_field/reference.py): four scrolling tileable octaves, each turned and with
// its own period, give fbm;
// far_field_rank(xz, lod) is the fraction of the layer whose fbm lies below this point's (per mip level:
// cover.py level_table, a blurred pattern ranked by its own quantiles; one fetch of far_rank_table, the
// rank baked as a function of fbm and level: cover.rank_table), and far_quantile(r) the volume's
// column sum at that rank (column_quantiles, cover.comp), so the far field is clouded as often, and as
// thick per cover, as the volume. Shared by the far-field pass (far.comp), the ray march's volumetric
// far field (clouds/raymarch/far.glsl) and the ground shadows and light shafts (clouds/volume/column.glsl
// with CLOUD_FAR_FIELD: field_column_tau × far_quantile); atmos/plugins/clouds/far_field/layer.py binds it.
#include "sky_layer/layer.glsl"
layout(binding = 5) uniform sampler2D octave0;
layout(binding = 6) uniform sampler2D octave1;
layout(binding = 7) uniform sampler2D octave2;
layout(binding = 8) uniform sampler2D octave3;
layout(binding = 25) uniform sampler2D far_rank_table;   // R32F (fbm, level) -> rank: cover.rank_table, linear, clamped
layout(std430, binding = 0) readonly buffer Cover { float cover; float column_quantiles[33]; };
uniform vec2 field_origin;         // a world xz near the view (the camera's)
uniform vec2 field_offsets[4];     // each octave's uv there, drift included (wrapped, float64 on the CPU)
uniform mat2 field_turns[4];       // world tiles -> octave k's uv: its turn / its period (clouds/far_field/pattern.py)
uniform vec4 field_lod_shift;      // log2 of each octave's period in tiles (its texels are that much larger)
#define FIELD_LEVELS 8     // far_rank_table's rows (cover.LEVELS)
uniform vec2 far_rank_span;        // far_rank_table's x of fbm f: (f - span.x) * span.y
uniform float field_first_level;   // the mip level of table row 0
uniform float field_tile_size;
uniform float field_mid_height;    // the layer's middle plane (world y)
uniform float field_column_tau;    // thickness · sigma_t · cell height: optical depth per summed cell
uniform float field_crossings[33]; // cover.pattern_crossings: the pattern's crossings of quantile k per tile
const float MIN_SLANT = 0.1;       // the cap on a slant's sin (about 6 degrees): the view's at the horizon, the sun's

// The volume's column sum (cells) at rank r (column_quantiles, linear between the 33): what the 2D far
// field (far.comp) and the march's (clouds/raymarch/far.glsl) take at a point of rank far_field_rank.
float far_quantile(float r) {
    float x = clamp(r, 0.0, 1.0) * 32.0;
    int k = min(int(x), 31);
    return mix(column_quantiles[k], column_quantiles[k + 1], x - float(k));
}

// The four octaves' fbm at world (x, z) = xz, per channel (pattern.py CHANNEL_STEPS: the point, the
// relief's samples toward the sun and away from it, the point again); lod: mip level of a texture
// repeating once per tile (octave k, repeating every 2^field_lod_shift[k] tiles, reads that much finer).
// Each octave turned and repeating at its own period: the sum repeats nowhere (pattern.py).
vec4 field_fbm(vec2 xz, float lod) {
    vec2 p = (xz - field_origin) / field_tile_size;
    vec4 l = max(vec4(lod) - field_lod_shift, 0.0);
    return SKY_LAYER_WEIGHTS.x * textureLod(octave0, field_offsets[0] + field_turns[0] * p, l.x)
         + SKY_LAYER_WEIGHTS.y * textureLod(octave1, field_offsets[1] + field_turns[1] * p, l.y)
         + SKY_LAYER_WEIGHTS.z * textureLod(octave2, field_offsets[2] + field_turns[2] * p, l.z)
         + SKY_LAYER_WEIGHTS.w * textureLod(octave3, field_offsets[3] + field_turns[3] * p, l.w);
}

// The table row (and the share of the next) that mip level lod reads.
float field_level(float lod) {
    return clamp(lod - field_first_level, 0.0, float(FIELD_LEVELS - 1));
}

// The rank of fbm f (per channel) among table level m = field_level(lod)'s: the fraction of its fbm at
// or below f, linear between its 33 quantiles, mixed between rows floor(m) and the next by the filter
// (texel centres: row k at y = (k + 0.5) / FIELD_LEVELS; the last row alone at m = FIELD_LEVELS - 1).
vec4 fbm_rank(vec4 f, float lod) {
    float y = (field_level(lod) + 0.5) / float(FIELD_LEVELS);
    vec4 x = (f - far_rank_span.x) * far_rank_span.y;
    return vec4(textureLod(far_rank_table, vec2(x.x, y), 0.0).r, textureLod(far_rank_table, vec2(x.y, y), 0.0).r,
                textureLod(far_rank_table, vec2(x.z, y), 0.0).r, textureLod(far_rank_table, vec2(x.w, y), 0.0).r);
}

// The rank (fbm_rank) of the point's fbm at world xz among its level's, per channel.
vec4 far_field_rank(vec2 xz, float lod) {
    return fbm_rank(field_fbm(xz, lod), lod);
}

// The relief at a point of ranks r (far_field_rank): the sun's extra optical depth through the layer's
// slope there, from the columns the relief's samples toward the sun and away from it hold (tau_cell:
// optical depth per summed cell): 3/16 of their difference (for a steady slope as much as the
// one-sided form it replaced, 3/8 of (mean over 1..3 steps toward the sun - here)) over the sun's
// height sin (capped at MIN_SLANT). 0 where the clouds are as thick both ways; as often up as down.
float far_relief(vec4 r, float tau_cell, float sun_y) {
    return 0.1875 * tau_cell * (far_quantile(r.y) - far_quantile(r.z)) / max(sun_y, MIN_SLANT);
}

// The octaves' sun transmittances s (the volume's own mean at the point's rank: RankLight) moved by the
// relief's optical depths d toward 0 (d > 0: more cloud toward the sun than away) or 1, at most as far
// as the nearer bound: odd in d, so a relief as often up as down leaves the mean light at s (lit sides
// facing the sun, shaded ones behind, and no light added).
vec4 relief_light(vec4 s, vec4 d) {
    return s - min(s, 1.0 - s) * tanh(clamp(d, -10.0, 10.0));      // clamped: tanh's exp overflows past ~44
}
