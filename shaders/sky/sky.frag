#version 430
// The analytic sky over a fullscreen triangle (sky/sky_pixel.glsl): what tests draw directly; the
// graph's sky pass is sky/sky.comp.
#include "lib/frame.glsl"
in vec2 v_uv;
out vec4 frag;
#include "sky/sky_pixel.glsl"

void main() {
    frag = sky_pixel(v_uv);
}
