// The ray march's volumetric far field (float64 reference: plugins/cloud_raymarch/far_reference.py).
// Beyond the simulated volume (and across its edge fade, weighted by 1 - the edge weight) the layer
// continues the volume's statistics: a point whose far-field fbm has rank r among its level's
// (far_field_rank, cloud_far_field/field.glsl: the same octaves and drift as the 2D far field and the
// ground shadows) gets the column of the volume's column sums at the same rank (column_quantiles,
// cloud_far_field/cover.comp: their edge-weighted quantiles, measured each frame), so the far layer is
// covered as often, and as thick per cover, as the volume. In profile units I = sum / (far_body · the
// layer's height in cells) = far_amount · sum (the column's integral of the profile over the height
// fraction h, 0 base, 1 top) the column is
//   top = FAR_BASE + x with far_above(FAR_BASE, top) = I   (thicker columns, taller clouds: rounded
//                                                           domes over the pattern's blobs)
//   profile = clamp((h - FAR_BASE) / FAR_BASE_SOFT + 0.5, 0, 1) * clamp((top - h) / FAR_TOP_SOFT, 0, 1)
//   density = far_body * profile * max(1, I / FAR_MAX)   (far_body: detail.glsl's K, a cloud body's
//                                                          density; past the tallest profile, denser)
// which the march then erodes with the detail noise like the volume's density. Light (volume.glsl's
// model): the sun transmittance from a three-step march toward the sun through the same profile, the
// column at each step from the light-march channels d.yzw (baked light_step tiles apart toward the
// sun: no extra fetch); the sky light from the profile's analytic columns above and below.
// Requires volume.glsl (sun_part, octave_weights, ambient_source, sun_dir) included first.
#include "cloud_far_field/field.glsl"

const float FAR_BASE = 0.1;       // the flat base's height fraction
const float FAR_BASE_SOFT = 0.05; // ramp of the base (centred on FAR_BASE)
const float FAR_TOP_SOFT = 0.3;   // ramp below the top: the shell the detail noise carves
const float FAR_MAX = 1.0 - FAR_BASE - 0.5 * FAR_TOP_SOFT;   // I of the tallest profile (top = 1)
uniform float far_lod_scale;      // octave texels per metre x a full-res pixel's angle (rad)
uniform vec2 far_band;            // (base y, height) of the layer (m)
uniform float far_body;           // density of a far cloud's body
uniform float far_amount;         // 1 / (far_body * the layer's height in cells): a column sum in I
uniform vec3 far_sun;             // (step toward the sun (m), channels per step, layer fraction per step)

// The columns I (profile units) at xz and at the three light-march channels; s: distance (m).
vec4 far_cover(vec2 xz, float s) {
    vec4 r = far_field_rank(xz, log2(max(far_lod_scale * s, 1e-6)));
    return far_amount * vec4(far_quantile(r.x), far_quantile(r.y), far_quantile(r.z), far_quantile(r.w));
}

float far_height(float y) {
    return (y - far_band.x) / far_band.y;
}

// (top, density factor) of a column I: far_above(FAR_BASE, top) * factor = I.
vec2 far_column(float I) {
    if (I > FAR_MAX) return vec2(1.0, I / FAR_MAX);
    float x = I >= 0.5 * FAR_TOP_SOFT ? I + 0.5 * FAR_TOP_SOFT : sqrt(2.0 * FAR_TOP_SOFT * I);
    return vec2(FAR_BASE + x, 1.0);
}

float far_profile(float h, float I) {
    if (I <= 0.0) return 0.0;
    vec2 col = far_column(I);
    return col.y * clamp((h - FAR_BASE) / FAR_BASE_SOFT + 0.5, 0.0, 1.0) * clamp((col.x - h) / FAR_TOP_SOFT, 0.0, 1.0);
}

// The profile's integral from h to the top (layer fractions), base ramp aside (centred on FAR_BASE, it
// adds about as much below FAR_BASE as it takes above).
float far_above(float h, float top) {
    float x = max(top - h, 0.0);
    return x >= FAR_TOP_SOFT ? x - 0.5 * FAR_TOP_SOFT : x * x / (2.0 * FAR_TOP_SOFT);
}

// The column at a fractional channel position x in [0, 3) of the light-march channels c.
float far_channel(vec4 c, float x) {
    int i = min(int(x), 2);
    return mix(c[i], c[i + 1], x - float(i));
}

// J (per unit extinction) of far-field density with columns c (channels) at height fraction h, seen along
// dir; sigma_t: extinction (1/m) at density 1.
vec3 far_source(vec4 c, float h, vec3 dir, float sigma_t) {
    float depth = 0.0;
    for (int k = 0; k < 3; ++k) {
        float x = (float(k) + 0.5) * far_sun.y;
        depth += far_profile(h + (float(k) + 0.5) * far_sun.z, far_channel(c, x));
    }
    float T = exp(-sigma_t * far_body * far_sun.x * depth);
    vec2 col = far_column(c.x);
    float hb = max(h, FAR_BASE), k = sigma_t * far_body * far_band.y * col.y;
    float up = k * far_above(hb, col.x), down = k * (far_above(FAR_BASE, col.x) - far_above(hb, col.x));
    return sun_part(octave_weights(T, up + down), dot(dir, sun_dir)) + ambient_source(up, down, dir.y);
}
