#version 430
// Render-graph test: red ramps with x across the target, green and blue are constant.
in vec2 v_uv;
out vec4 frag;
void main() { frag = vec4(v_uv.x, 0.25, 0.5, 1.0); }
