#version 430
// Ground: anti-aliased checker in albedo, Lambert sun light plus the Sun's sky ambient, fading with
// distance into the sky's horizon light (plugins/ground haze_color: dark at night, dim at twilight, no
// bright line at the horizon then), which hides the plane's edge.
// Alpha 1: opaque, hides the sky (color.a is the sky occlusion, atmos/render_core.py).
// camera_pos, sun_dir, sun_color, sky_ambient: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
in vec3 v_world;
out vec4 frag;
uniform vec3 albedo;
uniform float tile;
uniform float haze_rate;        // 1 / GroundSettings.haze_distance (0: no fade)
uniform vec3 haze_color;

void main() {
    vec2 p = v_world.xz / tile;
    vec2 w = fwidth(p) + 1e-4;
    vec2 i = 2.0 * (abs(fract((p - 0.5 * w) * 0.5) - 0.5) - abs(fract((p + 0.5 * w) * 0.5) - 0.5)) / w;
    float checker = 0.5 - 0.5 * i.x * i.y;
    vec3 base = albedo * mix(0.8, 1.1, checker);
    vec3 s = normalize(sun_dir);
    vec3 light = sun_color * max(s.y, 0.0) + sky_ambient;
    float dist = length(v_world - camera_pos);
    frag = vec4(mix(base * light, haze_color, 1.0 - exp(-dist * haze_rate)), 1.0);
}
