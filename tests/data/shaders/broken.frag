#version 430
// Test shader with a deliberate error on line 7 (used by tests/test_gpu_context.py).
uniform vec4 color;
out vec4 frag;
void main() {
    frag = color;
    frag.x = undefined_name;
}
