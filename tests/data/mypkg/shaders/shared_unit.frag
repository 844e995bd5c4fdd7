#version 430
// Two samplers at one unit, one of them from an included piece (tests/test_shader_path.py).
#include "mypkg/unit_piece.glsl"
layout(binding = 4) uniform sampler2D second;
out vec4 frag;
void main() { frag = texture(first, vec2(0.5)) + texture(second, vec2(0.5)); }
