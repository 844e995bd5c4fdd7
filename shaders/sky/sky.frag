#version 430
// The sky pass: a full-screen background of sky/sky.glsl along each pixel's view ray.
// Alpha 0: open sky (color.a is the sky occlusion, atmos/render_core.py).
// view_basis: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
in vec2 v_uv;
out vec4 frag;
#include "lib/view_ray.glsl"
#include "sky/sky.glsl"

void main() {
    frag = vec4(sky_color(view_ray_dir(v_uv, view_basis)), 0.0);
}
