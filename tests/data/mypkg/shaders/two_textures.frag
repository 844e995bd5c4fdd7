#version 430
// Two samplers at units 4 and 9, a third that the compiler drops (tests/test_shader_path.py).
#include "mypkg/unit_piece.glsl"
layout(binding = 9) uniform sampler2D second;
uniform sampler2D unused;        // dropped by the compiler: needs no unit
out vec4 frag;
void main() { frag = vec4(texelFetch(first, ivec2(0), 0).r, texelFetch(second, ivec2(0), 0).r, 0.0, 1.0); }
