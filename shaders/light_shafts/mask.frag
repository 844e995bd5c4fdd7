#version 430
// Light shafts, 1/3: occlusion mask at the mask's resolution. Sky pixels (depth 1) keep their colour
// scaled by the luminance above `threshold` (at most `ceiling`) times how open to the sky they are,
// 1 - color.a (color.a: the sky occlusion of atmos/render_core.py, so clouds drawn over the sky cut
// the mask however bright they are), times exp(-(r/radius)^2) near the sun; the rest is 0.
// plugins/light_shafts/reference.py: occlusion_mask.
out vec4 frag;
layout(binding = 0) uniform sampler2D scene_color;
layout(binding = 1) uniform sampler2D scene_depth;
uniform vec2 mask_size;
uniform vec2 sun_uv;
uniform float threshold;
uniform float ceiling;
uniform float radius;      // in screen heights
uniform float aspect;      // frame width / height

void main() {
    vec2 uv = gl_FragCoord.xy / mask_size;
    if (texture(scene_depth, uv).r < 1.0) {
        frag = vec4(0.0);
        return;
    }
    vec4 scene = texture(scene_color, uv);
    vec3 c = max(scene.rgb, vec3(0.0));
    float open_sky = 1.0 - clamp(scene.a, 0.0, 1.0);
    float lum = dot(c, vec3(0.2126, 0.7152, 0.0722));
    vec3 bright = c * (clamp(lum - threshold, 0.0, ceiling) * open_sky / max(lum, 1e-4));
    float r = length((uv - sun_uv) * vec2(aspect, 1.0));
    frag = vec4(bright * exp(-(r / radius) * (r / radius)), 0.0);
}
