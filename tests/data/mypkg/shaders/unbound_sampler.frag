#version 430
// A sampler without layout(binding = N) (tests/test_shader_path.py).
uniform sampler2D nowhere;
out vec4 frag;
void main() { frag = texture(nowhere, vec2(0.5)); }
