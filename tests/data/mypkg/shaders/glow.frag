#version 430
// A third-party plugin's shader (tests/test_shader_path.py): atmos's lib/ and the plugin's own piece.
#include "lib/view_ray.glsl"
#include "mypkg/palette.glsl"
in vec2 v_uv;
out vec4 frag;
uniform mat3 view_basis;       // atmos.camera.set_camera_uniforms

void main() {
    vec3 dir = view_ray_dir(v_uv, view_basis);
    frag = vec4(dir.y > 0.0 ? GLOW_UP : GLOW_DOWN, 1.0);
}
