#version 430
// The cloud field beyond the simulated volume (float64 reference: atmos/plugins/cloud_far_field/
// reference.py). The view ray meets the layer's middle plane y = field_mid_height at the view depth s;
// where that is in front of the scene, r = far_field_rank there (field.glsl: the fraction of the
// layer's fbm below the point's) and the column takes the volume's own
// column sum at the same rank (far_quantile: column_quantiles, cover.comp), so it is as thick per
// cover as the volume, from the medium, with no hand-set opacity:
//   tau = thickness * column_tau * far_quantile(r)   (column_tau = sigma_t * cell height)
//   alpha = (1 - exp(-tau / max(|dir.y|, MIN_SLANT))) * (1 - edge weight at the hit) * smoothstep(0, horizon_fade, |ray.y|)
// (the view crosses the column along its slant, capped at the horizon), lit by the cloud medium's own
// model (cloud_render/volume.glsl) with the volume's own light at the same rank (RankLight,
// light_by_rank.comp; as seen from above when the view looks down, else from below): the octaves' sun
// transmittances (lib/octaves.glsl) of the volume's columns of rank r, to the power `thickness`
// (optical depths scale with it), times the relief of the layer toward the sun, exp(-e_i relief) (e:
// volume.glsl octave_exponents, how fast each falls with optical depth) with
// relief = 0.5 (mean(tau of the four light-march channels) - tau) / max(sun_dir.y, MIN_SLANT) (the
// channels: the rank 0..3 light steps toward the sun; 0 on average), and, where the sets carry a
// diffusion field, its light from their mean (phi, F); sky light with tau half above, half below.
// Premultiplied (blend_over).
// frag_distance: (alpha * distance to the hit, alpha), "cloud_distance" when attached (atmos/composition.py).
#include "lib/view_ray.glsl"
#include "cloud_far_field/field.glsl"
#include "cloud_render/volume.glsl"
in vec2 v_uv;
out vec4 frag;
layout(location = 1) out vec4 frag_distance;   // blends by its own alpha
layout(binding = 9) uniform sampler2D scene_depth;
uniform mat3 view_basis;
uniform vec3 camera_pos;
uniform float near;
uniform float far;
uniform vec2 footprint_min;    // the volume's footprint (world xz)
uniform vec2 footprint_size;
uniform float thickness;
uniform float horizon_fade;
const float MIN_SLANT = 0.1;     // the horizon's slant cap (about 6 degrees)
layout(binding = 18) uniform sampler2D far_sun_by_rank;   // RankLight.sun: (rank, seen from above | below) -> the octaves' transmittances
layout(binding = 19) uniform sampler2D far_field_light;   // RankLight.field: (rank, seen from above | below) -> (phi, F)
uniform float lod_scale;       // texels per metre × a pixel's angle (rad): the mip level from the footprint,
                               // not from screen derivatives (the same under any camera roll)

void main() {
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
    vec4 col = thickness * column_tau * vec4(far_quantile(r.x), far_quantile(r.y), far_quantile(r.z), far_quantile(r.w));
    float tau = col.x;
    float alpha = (1.0 - exp(-tau / max(abs(dir.y), MIN_SLANT))) * fade;
    vec2 at = vec2(r.x, dir.y < 0.0 ? 0.25 : 0.75);        // row 0: seen from above, 1: from below
    // relief: the sun's extra optical depth through the channels toward it over a column as thick all
    // round (0 on average): lit edges facing the sun, shaded ones behind
    float relief = 0.5 * (dot(col, vec4(0.25)) - tau) / max(sun_dir.y, MIN_SLANT);
    vec4 sun = min(pow(max(textureLod(far_sun_by_rank, at, 0.0), 0.0), vec4(thickness)) * exp(-relief * octave_exponents()),
                   1.0);
    vec3 light = sun_part(octave_weights_of(sun), dot(dir, sun_dir)) + ambient_source(0.5 * tau, 0.5 * tau, dir.y)
               + (ms_diffusion > 0.0 ? diffusion_light(textureLod(far_field_light, at, 0.0), dir) : vec3(0.0));
    frag = vec4(light * alpha, alpha);
    frag_distance = vec4(alpha * length(hit - camera_pos), alpha, 0.0, alpha);
}
