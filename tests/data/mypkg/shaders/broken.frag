#version 430
// A third-party shader with a deliberate error on line 7 (tests/test_shader_path.py).
#include "lib/view_ray.glsl"
in vec2 v_uv;
out vec4 frag;
void main() {
    frag = vec4(undefined_glow, 1.0);
}
