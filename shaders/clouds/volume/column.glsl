// Optical depth toward the sun through the cloud layer from the density maps (thesis 7.3.1): a point
// is projected along the direction toward the sun onto the middle of the layer (with a cloud type, on
// to the height of the type's mass centre: centre_shift), where the top-view
// summed density mix(A, B, t) (layer 0 of the density maps, each set at its own placement) is read
// bilinearly, zero outside the volume, times the volume's edge fade there, times the fraction of the layer above the point;
// with CLOUD_FAR_FIELD defined the far field's column (clouds/far_field/field.glsl) adds its optical depth
// with the complementary weight, so shadows continue past the volume: the column the far field draws
// (far.comp), field_column_tau (thickness · sigma_t · cell height) × the volume's column sum at the
// rank of the point where the sun's ray meets the middle plane (far_quantile(far_field_rank)). Baked per frame
// into the cloud shadow map (clouds/shadows/bake.comp), which the ground shadows and light shafts read;
// their exact paths (CLOUD_SHADOW_EXACT, SHAFT_EXACT_SHADOWS) still call it;
// plugins/clouds/shadows/reference.py sun_optical_depth is the same in numpy.
// Where the clouds are drawn with a cloud type (clouds/volume/shape.glsl: cloud_type >= 0, set by
// column.py column_uniforms from what the renderer publishes), every column sum becomes the column of
// the shape drawn (typed_column): a stratus deck's shadow as thin as the sheet drawn, a congestus's as
// deep as its tower.
layout(binding = 0) uniform sampler2DArray sums_a;
layout(binding = 1) uniform sampler2DArray sums_b;
uniform float extinction;      // sigma × strength, per cell of summed density
uniform float t;               // interpolation factor between A and B
uniform ivec2 a_shift;         // (x, z) cells from B's column to A's at the same place (CloudSets.a_shift)
uniform vec3 layer_min;        // world corner of cell (0, 0, 0): (origin.x·cx, base_altitude, origin.z·cz)
uniform vec3 cell_size;
uniform ivec3 shape;
uniform float edge_fade;       // CloudSettings.edge_fade: columns fade with the volume's edge (clouds/volume/edge.glsl)
uniform float type_rise;       // layer heights above the middle the columns are read at (shape.py centre_rise)
#include "clouds/volume/edge.glsl"
#include "clouds/volume/shape.glsl"
#ifdef CLOUD_FAR_FIELD
#include "clouds/far_field/field.glsl"
#endif

const float MIN_SUN_HEIGHT = 1e-4;
layout(binding = 27) uniform sampler2D typed_columns;   // shape.py column_table: (sqrt(m / COLUMN_FULL), t) -> G

// The column sum (summed density over the layer's shape.y cells) of the shape drawn over world point
// xz for a simulated column sum `sum`: shape.y x G(sum / shape.y, t), G the mean of the type's shaped
// density over its height (shape.py column_mean), read from its table with 4 fetches (bilinear in
// float32: the hardware filter's weights have 8 bits on some GPUs); `sum` itself where no type is drawn
// (cloud_type < 0).
float typed_column(float sum, vec2 xz) {
    if (cloud_type < 0.0 || sum <= 0.0) return sum;
    float ny = float(shape.y);
    ivec2 n = textureSize(typed_columns, 0);
    vec2 x = vec2(sqrt(clamp(sum / (ny * COLUMN_FULL), 0.0, 1.0)), clamp(cloud_type_at(xz), 0.0, 1.0)) * vec2(n - 1);
    ivec2 i = min(ivec2(x), n - 2);
    vec2 f = x - vec2(i);
    float g = mix(mix(texelFetch(typed_columns, i, 0).r, texelFetch(typed_columns, i + ivec2(1, 0), 0).r, f.x),
                  mix(texelFetch(typed_columns, i + ivec2(0, 1), 0).r, texelFetch(typed_columns, i + ivec2(1, 1), 0).r, f.x), f.y);
    return ny * g;
}

// Metres (x, z) from a middle-plane point along the sun's ray to the height type_rise layers above the
// middle (shape.py centre_rise: the mass centre of the type drawn; 0 untyped): the columns are read
// there, so a stratus sheet's shadow and a congestus tower's fall where their clouds are.
vec2 centre_shift(vec3 sun_dir) {
    return type_rise * float(shape.y) * cell_size.y / max(sun_dir.y, MIN_SUN_HEIGHT) * sun_dir.xz;
}

bool outside(ivec2 c) {
    return any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c, shape.xz));
}

// Column c of B's placement (layer_min), A read at its own (c + a_shift): zero outside either volume.
float column(ivec2 c) {
    if (outside(c)) return 0.0;
    ivec2 ca = c + a_shift;
    float a = outside(ca) ? 0.0 : texelFetch(sums_a, ivec3(ca, 0), 0).r;
    return mix(a, texelFetch(sums_b, ivec3(c, 0), 0).r, t);
}

// Bilinear, texel i centred at i, zero outside the volume.
float column_sum(vec2 p) {
    if (any(lessThanEqual(p, vec2(-1.0))) || any(greaterThanEqual(p, vec2(shape.xz)))) return 0.0;
    vec2 i0 = floor(p);
    vec2 f = p - i0;
    ivec2 i = ivec2(i0);
    return mix(mix(column(i), column(i + ivec2(1, 0)), f.x),
               mix(column(i + ivec2(0, 1)), column(i + ivec2(1, 1)), f.x), f.y);
}

// The sun's columns through volume texel v (texel i centred at i) whose middle-plane point is world xz,
// read where that ray meets the shape drawn (centre_shift): (column sum × edge fade, far-field column
// sum × (1 − fade)), per unit extinction; the cloud shadow map (clouds/shadows/bake.comp) bakes exactly this.
vec2 sun_columns(vec2 v, vec2 xz, vec3 sun_dir) {
    vec2 shift = centre_shift(sun_dir);
    v += shift / cell_size.xz;
    xz += shift;
    float fade = cloud_edge_weight((v + 0.5) / vec2(shape.xz), edge_fade);
    vec2 c = vec2(fade > 0.0 ? typed_column(column_sum(v), xz) * fade : 0.0, 0.0);
#ifdef CLOUD_FAR_FIELD
    // beyond the volume the far field's cover continues with the complementary weight (field.glsl)
    if (fade < 1.0) c.y = typed_column(far_quantile(far_field_rank(xz, 0.0).x), xz) * (1.0 - fade);
#endif
    return c;
}

// Optical depth between world point p and the sun (sun_dir unit, toward the sun) through the clouds.
float sun_optical_depth(vec3 p, vec3 sun_dir) {
    float thickness = float(shape.y) * cell_size.y;
    float run = max(layer_min.y + 0.5 * thickness - p.y, 0.0) / max(sun_dir.y, MIN_SUN_HEIGHT);
    vec3 q = p + run * sun_dir;
    vec2 texel = (q.xz - layer_min.xz) / cell_size.xz - 0.5;
    float above = clamp((layer_min.y + thickness - p.y) / thickness, 0.0, 1.0);
    vec2 c = sun_columns(texel, q.xz, sun_dir);
#ifdef CLOUD_FAR_FIELD
    return (extinction * c.x + field_column_tau * c.y) * above;
#else
    return extinction * c.x * above;
#endif
}
