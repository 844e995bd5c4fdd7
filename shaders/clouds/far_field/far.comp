#version 430
// The cloud field beyond the simulated volume (float64 reference: atmos/plugins/clouds/far_field/
// reference.py). The view ray meets the layer's middle plane y = field_mid_height at the view depth s;
// where that is in front of the scene, r = far_field_rank there (field.glsl: the fraction of the
// layer's fbm below the point's) and the column takes the volume's own column sum at the same rank
// (far_quantile: column_quantiles, cover.comp), so it is as thick per cover as the volume, from the
// medium, with no hand-set opacity; seen at a slant, the layer's clouds (RankLight's thickness at the
// median covered rank high) show their sides and cover more of the view (slant_rank: rank r', factor f):
//   tau = thickness * column_tau * f * far_quantile(r')   (column_tau = sigma_t * cell height)
//   alpha = (1 - exp(-tau / max(|dir.y|, MIN_SLANT))) * (1 - edge weight at the hit) * smoothstep(0, horizon_fade, |ray.y|)
// (MIN_SLANT: field.glsl's cap on the slant at the horizon), lit by the cloud medium's own
// model (clouds/volume/volume.glsl) with the volume's own light at the same rank (RankLight,
// light_by_rank.comp; as seen from above when the view looks down, else from below): the octaves' sun
// transmittances (lib/octaves.glsl) of the volume's columns of rank r, to the power `thickness`, under the
// sun's colour at the height that light comes from (RankLight.height, volume.glsl sun_source_at)
// (optical depths scale with it), moved by the relief toward the sun (field.glsl far_relief,
// relief_light: lit edges facing the sun, shaded ones behind, no light added), and, where the sets
// carry a diffusion field, its light from their mean (phi, F); sky light with tau half above, half below.
// One compute invocation per pixel composites the premultiplied result onto the colour in place (as
// blend_over would: layer + (1 - alpha) colour, alpha too) and, FAR_DISTANCE 1, its distance (alpha *
// distance to the hit, alpha) onto "cloud_distance" (atmos/composition.py) with the same weights;
// FAR_DISTANCE 2 (its first writer, no clear before) stores it at every pixel, (0, 0) where no layer.
// The camera is the frame block's (lib/frame.glsl).
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#include "clouds/far_field/field.glsl"
#include "clouds/volume/volume.glsl"
#include "lib/over.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) uniform image2D color_image;
#if FAR_DISTANCE
layout(binding = 1, rg32f) uniform image2D distance_image;
#endif
layout(binding = 9) uniform sampler2D scene_depth;
uniform vec2 footprint_min;    // the volume's footprint (world xz)
uniform vec2 footprint_size;
uniform float thickness;
uniform float horizon_fade;
uniform float layer_height;    // the volume's layer (m)
layout(binding = 18) uniform sampler2D far_sun_by_rank;   // RankLight.sun: (rank, seen from above | below) -> the octaves' transmittances
layout(binding = 21) uniform sampler2D far_thickness_by_rank;   // RankLight.thickness: rank -> the clouds' height / layer_height
layout(binding = 24) uniform sampler2D far_height_by_rank;   // RankLight.height: (rank, seen from above | below) -> where its light comes from
layout(binding = 19) uniform sampler2D far_field_light;   // RankLight.field: (rank, seen from above | below) -> (phi, F)
uniform float lod_scale;       // texels per metre × a pixel's angle (rad): the mip level from the footprint,
                               // not from screen derivatives (the same under any camera roll)

// A RankLight texture (rank, row) at uv: bilinear, clamp to edge, weights in float32 (np.interp in the
// reference; a texture unit's 8-bit sub-texel weights would move the clouds' height between ranks).
vec4 rank_lookup(sampler2D s, vec2 uv) {
    ivec2 n = textureSize(s, 0);
    vec2 p = clamp(uv * vec2(n) - 0.5, vec2(0.0), vec2(n - 1));
    ivec2 i = ivec2(p), j = min(i + 1, n - 1);      // p >= 0: ivec2 is its floor
    vec2 f = p - vec2(i), g = 1.0 - f;
    return g.y * (g.x * texelFetch(s, i, 0) + f.x * texelFetch(s, ivec2(j.x, i.y), 0))
         + f.y * (g.x * texelFetch(s, ivec2(i.x, j.y), 0) + f.x * texelFetch(s, j, 0));
}

// (rank, optical depth factor) of a point of rank r of a layer of clouds `height` (m) high seen with
// the view's cot(elevation) `cot`. Along a line the pattern changes cover n times per metre
// (field_crossings at the cover's quantile, per tile): chords of mean length 2c / n, gaps 2 (1 - c) / n,
// taken as exponential. A cloud as a spheroid of those radii (a = c / n across, b = height / 2 up) seen
// at that slant throws a shadow on the middle plane sqrt(a^2 + b^2 cot^2) long (half), so each cloud
// widens by S = 2 (sqrt(a^2 + b^2 cot^2) - a) along the view, and the layer covers
// c' = 1 - (1 - c) exp(-S / gap) of it; the ranks above 1 - c' are spread over the covered ones
// (1 - c .. 1) and the optical depth scaled by c / c': the mean optical depth along the ray stays the
// layer's (a 3D layer's clouds show their sides; toward the horizon the gaps close).
vec2 slant_rank(float r, float height, float cot) {
    float c = clamp(cover, 0.0, 1.0);
    float x = clamp(1.0 - c, 0.0, 1.0) * 32.0;
    int k = min(int(x), 31);
    float n = mix(field_crossings[k], field_crossings[k + 1], x - float(k)) / field_tile_size;
    if (!(c > 0.0 && c < 1.0 && n > 0.0 && height > 0.0)) return vec2(r, 1.0);
    float a = c / n, b = 0.5 * height;
    float widen = 2.0 * (sqrt(a * a + b * b * cot * cot) - a);
    float c2 = 1.0 - (1.0 - c) * exp(-widen * n / (2.0 * (1.0 - c)));
    return vec2(1.0 - c + (r - (1.0 - c2)) * c / c2, c / c2);
}

// The far field over the pixel at v_uv: (premultiplied light, alpha) and (alpha * distance, alpha, 0, alpha).
void far_pixel(vec2 v_uv, out vec4 frag, out vec4 frag_distance) {
    frag = vec4(0.0);
    frag_distance = vec4(0.0);
    vec3 ray = view_ray(v_uv, view_basis);
    float s = (field_mid_height - camera_pos.y) / ray.y;            // view depth of the plane
    if (!(s > 0.0) || isinf(s)) return;
    float depth = texture(scene_depth, v_uv).r;
    // behind the scene: gone; a soft edge over the last 20 % (terrain at the horizon meets the layer there)
    float open = depth < 1.0 ? smoothstep(0.8 * s, s, view_depth(depth, near, far)) : 1.0;
    if (open <= 0.0) return;
    vec3 hit = camera_pos + s * ray;
    float w = 1.0 - cloud_edge_weight((hit.xz - footprint_min) / footprint_size, edge_fade);
    vec3 dir = normalize(ray);
    float fade = open * w * smoothstep(0.0, horizon_fade, abs(dir.y));
    if (fade <= 0.0) return;
    float lod = log2(max(lod_scale * length(hit - camera_pos) / max(abs(dir.y), 1e-3), 1e-6));
    vec4 r = far_field_rank(hit.xz, lod);
    // the clouds' height h: RankLight's thickness at the median covered rank; seen at a slant their
    // sides widen the layer's cover (slant_rank)
    float height = layer_height * rank_lookup(far_thickness_by_rank, vec2(1.0 - 0.5 * cover, 0.5)).r;
    vec2 slanted = slant_rank(r.x, height, length(dir.xz) / max(abs(dir.y), MIN_SLANT));
    float tau = thickness * column_tau * slanted.y * far_quantile(slanted.x);
    float alpha = (1.0 - exp(-tau / max(abs(dir.y), MIN_SLANT))) * fade;
    if (!(alpha > 0.0)) {                                // none (thickness 0: no pow(0, 0) below)
        frag = vec4(0.0);
        frag_distance = vec4(0.0);
        return;
    }
    vec2 at = vec2(slanted.x, dir.y < 0.0 ? 0.25 : 0.75);  // row 0: seen from above, 1: from below
    // the sun's light moved by the relief: lit edges facing the sun, shaded ones behind, none added
    float relief = far_relief(r, thickness * column_tau, light_dir.y);
    vec4 sun = relief_light(clamp(pow(max(rank_lookup(far_sun_by_rank, at), 0.0), vec4(thickness)), 0.0, 1.0),
                            relief * octave_exponents());
    vec3 source = sun_source_at(rank_lookup(far_height_by_rank, at).r);
    vec3 light = sun_part(octave_weights_of(sun), dot(dir, light_dir), source) + ambient_source(0.5 * tau, 0.5 * tau, dir.y)
               + (ms_diffusion > 0.0 ? diffusion_light(rank_lookup(far_field_light, at), dir, source) : vec3(0.0));
    frag = vec4(min(light, vec3(HDR_MAX)) * alpha, alpha);   // volume.glsl: never inf in float16
    frag_distance = vec4(alpha * length(hit - camera_pos), alpha, 0.0, alpha);
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(px, size))) return;
    vec4 layer, distance;
    far_pixel((vec2(px) + 0.5) / vec2(size), layer, distance);
#if FAR_DISTANCE == 2
    imageStore(distance_image, px, vec4(layer.a > 0.0 ? distance.rg : vec2(0.0), 0.0, 0.0));
#endif
    if (!(layer.a > 0.0)) return;                        // nothing in front: the pixel stays as it is
    imageStore(color_image, px, over(layer, imageLoad(color_image, px)));
#if FAR_DISTANCE == 1
    imageStore(distance_image, px, vec4(over(distance.rg, imageLoad(distance_image, px).rg), 0.0, 0.0));
#endif
}
