#version 430
// Instanced meshes (atmos.plugins.mesh): per vertex a position and normal in model space, per instance
// a model matrix, its change since the last frame (model now − model then: the vertex's world motion
// is in_change · position, exactly 0 for a still instance) and a colour.
// view_proj: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
in vec3 in_position;
in vec3 in_normal;
in mat4 in_model;
in mat4 in_change;
in vec3 in_color;
out vec3 v_normal;
out vec3 v_color;
out vec3 v_motion;

void main() {
    vec4 world = in_model * vec4(in_position, 1.0);
    v_normal = transpose(inverse(mat3(in_model))) * in_normal;
    v_color = in_color;
    v_motion = (in_change * vec4(in_position, 1.0)).xyz;
    gl_Position = jitter_clip(view_proj * world);
}
