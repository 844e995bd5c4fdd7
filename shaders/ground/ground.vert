#version 430
// Ground plane vertices (x, z) at height 0.
in vec2 in_xz;
out vec3 v_world;
uniform mat4 view_proj;
void main() {
    v_world = vec3(in_xz.x, 0.0, in_xz.y);
    gl_Position = view_proj * vec4(v_world, 1.0);
}
