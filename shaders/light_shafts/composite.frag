#version 430
// Light shafts, 3/3: the blurred shafts, upsampled bilinearly, added onto the scene (blend ONE, ONE).
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D shafts;

void main() {
    frag = vec4(texture(shafts, v_uv).rgb, 0.0);
}
