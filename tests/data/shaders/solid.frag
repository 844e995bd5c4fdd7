#version 430
// Test shader: fills the target with one colour.
uniform vec4 color;
out vec4 frag;
void main() { frag = color; }
