#version 430
// The cloud layer on the sky: where nothing was drawn (depth 1), the view ray meets the plane
// y = altitude; the four scrolling octaves give fbm (one fetch each), shaded by sky_layer/layer.glsl.
// Premultiplied (light, coverage), blended ONE, ONE_MINUS_SRC_ALPHA on colour and alpha: the layer
// adds its cover to color.a, the sky occlusion (atmos/render_core.py).
// view_basis, camera_pos: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#include "sky_layer/layer.glsl"
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D octave0;
layout(binding = 1) uniform sampler2D octave1;
layout(binding = 2) uniform sampler2D octave2;
layout(binding = 3) uniform sampler2D octave3;
layout(binding = 4) uniform sampler2D scene_depth;
uniform vec2 offsets[4];       // scroll of each octave (tiles, wrapped to [0, 1))
uniform float altitude;
uniform float tile_size;
uniform float horizon_fade;
uniform float emptiness;
uniform float sharpness;
uniform float thickness;
uniform vec3 color;
uniform vec3 lit_color;
uniform vec3 light;

void main() {
    frag = vec4(0.0);                              // no cover: colour and alpha kept
    if (texture(scene_depth, v_uv).r < 1.0) return;
    vec3 dir = view_ray_dir(v_uv, view_basis);
    float t = (altitude - camera_pos.y) / max(dir.y, 1e-6);
    if (dir.y <= 1e-6 || t <= 0.0) return;
    vec2 uv = (camera_pos.xz - floor(camera_pos.xz / tile_size) * tile_size + dir.xz * t) / tile_size;
    vec4 fbm = SKY_LAYER_WEIGHTS.x * texture(octave0, uv + offsets[0])
             + SKY_LAYER_WEIGHTS.y * texture(octave1, uv + offsets[1])
             + SKY_LAYER_WEIGHTS.z * texture(octave2, uv + offsets[2])
             + SKY_LAYER_WEIGHTS.w * texture(octave3, uv + offsets[3]);
    float fade = smoothstep(0.0, horizon_fade, dir.y);
    frag = sky_layer_shade(fbm, emptiness, sharpness, thickness, color, lit_color, light, fade);
}
