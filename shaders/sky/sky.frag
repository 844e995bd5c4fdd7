#version 430
// The sky pass: a full-screen background of sky/sky.glsl along each pixel's view ray.
in vec2 v_uv;
out vec4 frag;
uniform mat3 view_basis;    // plugins/sky/shader.py:view_basis (rays independent of near/far)
#include "sky/sky.glsl"

void main() {
    frag = vec4(sky_color(normalize(view_basis * vec3(v_uv * 2.0 - 1.0, 1.0))), 1.0);
}
