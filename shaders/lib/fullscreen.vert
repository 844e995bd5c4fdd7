#version 430
// A triangle that covers the viewport, drawn with no vertex buffer (render(vertices=3)): from gl_VertexID
// alone, at mid depth.
out vec2 v_uv;
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    v_uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
