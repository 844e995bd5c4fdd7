// The ray march's volumetric far field (float64 reference: plugins/clouds/raymarch/far_reference.py).
// Beyond the simulated volume (and across its edge fade, weighted by 1 - the edge weight) the layer
// continues the volume's statistics: a point whose far-field fbm has rank r among its level's
// (far_field_rank, clouds/far_field/field.glsl: the same octaves and drift as the 2D far field and the
// ground shadows) gets the column of the volume's column sums at the same rank (far_quantile:
// column_quantiles, clouds/far_field/cover.comp: their edge-weighted quantiles, measured each frame)
// with the volume's own vertical shape at that rank (far_profile, measured in the same pass: the mean
// profile of the volume's covered columns in rank interval r, per unit column sum; G the share of the
// column above), so the far layer is covered as often, as thick per cover and at the same heights as
// the volume:
//   density(r, h) = far_quantile(r) * far_profile(r, h).R       (h: height fraction, 0 base, 1 top)
// or, with a cloud type, shape.glsl's type_density(far_quantile(r) / ny, h, cloud_type_at(xz)),
// which the march then erodes with the detail noise like the volume's density. Light (volume.glsl's
// model): the octaves' sun transmittances are the volume's own mean at the point's rank and height
// (far_sun_profile: light_by_rank.comp's sun_profile), so far clouds shade each other as much as the
// volume's do at any sun (a short march of their own saw 85 m of a 4.6 deg sun's path: sunset's far
// clouds 1.7x too bright toward the sun); moved by the relief as the 2D far field's (field.glsl
// far_relief, relief_light: from the same fetch's channels, lit sides facing the sun, none added);
// the sky light from the column above and below: column_tau * far_quantile(r) * (G, 1 - G);
// with a diffusion field, its light (diffusion_light) from the field's mean (phi, F) over the volume's
// columns of rank r at height h (far_field_light_profile: light_by_rank.comp's field_profile).
// under the sun's colour at its height (sun_source_at).
// Requires shape.glsl and volume.glsl (sun_part, sun_source_at, octave_weights_of, octave_exponents, ambient_source, light_dir, column_tau)
// included first.
#include "clouds/far_field/field.glsl"

uniform float far_lod_scale;      // octave texels per metre x a full-res pixel's angle (rad)
uniform vec2 far_band;            // (base y, height) of the layer (m)
layout(binding = 14) uniform sampler2D far_profile;   // FarFieldLayer.profile: (rank, h) -> (R, G), clamped
layout(binding = 20) uniform sampler2D far_field_light_profile;   // RankLight.field_profile: (rank, h) -> (phi, F)
layout(binding = 22) uniform sampler2D far_sun_profile;   // RankLight.sun_profile: (rank, h) -> the octaves' transmittances

// The ranks at xz and at the relief's samples (field.glsl's channels); s: distance (m).
vec4 far_ranks(vec2 xz, float s) {
    return far_field_rank(xz, log2(max(far_lod_scale * s, 1e-6)));
}

float far_height(float y) {
    return (y - far_band.x) / far_band.y;
}

// The far field's density at rank r and height fraction h (0 outside the layer) at world point xz; with a
// cloud type (shape.glsl, included first) the type's (there) shape of the column sum at r over the layer's
// ny cells.
float far_density(float r, float h, float ny, vec2 xz) {
    if (h < 0.0 || h > march_top) return 0.0;
    if (cloud_type >= 0.0) return type_density(far_quantile(r) / ny, h, cloud_type_at(xz));
    return far_quantile(r) * textureLod(far_profile, vec2(r, h), 0.0).r;
}

// J (per unit extinction) of far-field density with ranks c (far_ranks) at height fraction h, seen along
// dir.
vec3 far_source(vec4 c, float h, vec3 dir) {
    vec2 at = vec2(c.x, clamp(h, 0.0, 1.0));
    vec3 source = sun_source_at(clamp(h, 0.0, march_top));   // the volume's heights: the same band (towers too)
    vec4 sun = relief_light(textureLod(far_sun_profile, at, 0.0),
                            far_relief(c, column_tau, light_dir.y) * octave_exponents());
    float column = column_tau * far_quantile(c.x), above = textureLod(far_profile, at, 0.0).g;
    float up = column * above, down = column * (1.0 - above);
    vec3 field = ms_diffusion > 0.0
               ? diffusion_light(textureLod(far_field_light_profile, at, 0.0), dir, source) : vec3(0.0);
    return sun_part(octave_weights_of(sun), dot(dir, light_dir), source) + ambient_source(up, down, dir.y) + field;
}
