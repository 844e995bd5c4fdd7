#version 430
// Render-graph test: only ever used by passes that get culled, so it must never be compiled.
out vec4 frag;
void main() { frag = vec4(1.0, 0.0, 1.0, 1.0); }
