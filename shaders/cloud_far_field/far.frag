#version 430
// The cloud field beyond the simulated volume (float64 reference: atmos/plugins/cloud_far_field/
// reference.py). The view ray meets the layer's middle plane y = mid_height at the view depth s;
// where that is in front of the scene, four scrolling tileable octaves (the 2D sky layer's) give fbm,
// remapped from the threshold that leaves the simulation's cover (cover.comp) of the layer clouded:
//   d = remap(fbm, e, e + softness), amount = the sky layer's light march of d toward the sun,
//   alpha = (1 - exp(-thickness d.x)) * (1 - edge weight at the hit) * smoothstep(0, horizon_fade, |ray.y|)
// lit by the cloud medium's own model (cloud_render/volume.glsl): sun transmittance exp(-optical_depth
// amount), column optical depth optical_depth d.x (half above, half below). Premultiplied (blend_over).
// frag_distance: (alpha * distance to the hit, alpha), "cloud_distance" when attached (atmos/composition.py).
#include "lib/view_ray.glsl"
#include "sky_layer/layer.glsl"
#include "cloud_render/volume.glsl"
in vec2 v_uv;
out vec4 frag;
layout(location = 1) out vec4 frag_distance;   // blends by its own alpha
layout(binding = 5) uniform sampler2D octave0;
layout(binding = 6) uniform sampler2D octave1;
layout(binding = 7) uniform sampler2D octave2;
layout(binding = 8) uniform sampler2D octave3;
layout(binding = 9) uniform sampler2D scene_depth;
layout(std430, binding = 0) readonly buffer Cover { float cover; };
uniform mat3 view_basis;
uniform vec3 camera_pos;
uniform float near;
uniform float far;
uniform vec2 camera_uv;        // the camera's xz in tiles, wrapped to [0, 1) (float64 on the CPU)
uniform vec2 offsets[4];       // drift of each octave (tiles, wrapped)
uniform float quantiles[33];   // cover.fbm_quantiles
uniform float mid_height;
uniform vec2 footprint_min;    // the volume's footprint (world xz)
uniform vec2 footprint_size;
uniform float tile_size;
uniform float softness;
uniform float thickness;
uniform float optical_depth;
uniform float horizon_fade;
uniform float lod_scale;       // texels per metre × a pixel's angle (rad): the mip level from the footprint,
                               // not from screen derivatives (the same under any camera roll)

float threshold(float c) {
    float x = (1.0 - clamp(c, 0.0, 1.0)) * 32.0;
    int k = min(int(x), 31);
    return mix(quantiles[k], quantiles[k + 1], x - float(k));
}

void main() {
    frag = vec4(0.0);
    frag_distance = vec4(0.0);
    vec3 ray = view_ray(v_uv, view_basis);
    float s = (mid_height - camera_pos.y) / ray.y;            // view depth of the plane
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
    vec2 uv = camera_uv + (hit.xz - camera_pos.xz) / tile_size;
    float lod = log2(max(lod_scale * length(hit - camera_pos) / max(abs(dir.y), 1e-3), 1e-6));
    vec4 fbm = SKY_LAYER_WEIGHTS.x * textureLod(octave0, uv + offsets[0], lod)
             + SKY_LAYER_WEIGHTS.y * textureLod(octave1, uv + offsets[1], lod)
             + SKY_LAYER_WEIGHTS.z * textureLod(octave2, uv + offsets[2], lod)
             + SKY_LAYER_WEIGHTS.w * textureLod(octave3, uv + offsets[3], lod);
    float e = threshold(cover);
    vec4 d = sky_layer_remap(fbm, e, e + softness);
    float amount = dot(max(d - SKY_LAYER_RAY, 0.0), vec4(0.25));
    float alpha = (1.0 - exp(-thickness * d.x)) * fade;
    float tau = optical_depth * d.x;
    vec3 light = sun_part(octave_weights(exp(-optical_depth * amount), tau), dot(dir, sun_dir))
               + ambient_source(0.5 * tau, 0.5 * tau, dir.y);
    frag = vec4(light * alpha, alpha);
    frag_distance = vec4(alpha * length(hit - camera_pos), alpha, 0.0, alpha);
}
