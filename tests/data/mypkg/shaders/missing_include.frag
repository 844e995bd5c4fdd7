#version 430
// Includes a file that is nowhere on the search path (tests/test_shader_path.py).
#include "mypkg/not_shipped.glsl"
out vec4 frag;
void main() { frag = vec4(1.0); }
