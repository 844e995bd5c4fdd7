// Body of lib/fullscreen.vert: a viewport-covering triangle from gl_VertexID alone, at clip depth
// FULLSCREEN_Z (0: mid depth; lib/fullscreen_far.vert: 1, the far plane).
#ifndef FULLSCREEN_Z
#define FULLSCREEN_Z 0.0
#endif
out vec2 v_uv;
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    v_uv = p;
    gl_Position = vec4(p * 2.0 - 1.0, FULLSCREEN_Z, 1.0);
}
