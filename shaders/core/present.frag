#version 430
// Present: HDR scene colour -> display. Exposure, ACES-fitted tone curve, sRGB encoding.
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D hdr;
uniform float exposure;

vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

void main() {
    vec3 c = texture(hdr, v_uv).rgb * exposure;
    c = aces(max(c, vec3(0.0)));
    frag = vec4(pow(c, vec3(1.0 / 2.2)), 1.0);
}
