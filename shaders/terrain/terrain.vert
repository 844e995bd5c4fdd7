#version 430
// Terrain vertices: world position and normal straight through (the heightfield is in world space).
// view_proj: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
in vec3 in_position;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;
void main() {
    v_world = in_position;
    v_normal = in_normal;
    gl_Position = jitter_clip(view_proj * vec4(in_position, 1.0));
}
