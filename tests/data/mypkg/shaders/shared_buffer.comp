#version 430
// Two storage blocks at one binding (tests/test_shader_path.py).
layout(local_size_x = 1) in;
layout(std430, binding = 1) readonly buffer In { float a[]; };
layout(std430, binding = 1) writeonly buffer Out { float b[]; };
void main() { b[0] = a[0]; }
