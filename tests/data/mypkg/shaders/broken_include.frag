#version 430
// Includes a piece of this plugin whose line 3 is wrong (tests/test_shader_path.py).
#include "mypkg/broken_piece.glsl"
out vec4 frag;
void main() { frag = vec4(piece(), 1.0); }
