#version 430
// Ground plane vertices (x, z) at height 0.
// view_proj: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
in vec2 in_xz;
out vec3 v_world;
void main() {
    v_world = vec3(in_xz.x, 0.0, in_xz.y);
    gl_Position = jitter_clip(view_proj * vec4(v_world, 1.0));
}
