#version 430
// Terrain vertices: world position and normal straight through (the heightfield is in world space).
in vec3 in_position;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;
uniform mat4 view_proj;
void main() {
    v_world = in_position;
    v_normal = in_normal;
    gl_Position = view_proj * vec4(in_position, 1.0);
}
