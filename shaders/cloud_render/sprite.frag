#version 430
// A soft cloud particle: opacity 1 - exp(-tau × falloff), premultiplied (blend ONE, ONE_MINUS_SRC_ALPHA).
layout(binding = 4) uniform sampler2D particle;
flat in vec3 v_light;
flat in float v_tau;
flat in float v_coverage;
out vec4 frag;

void main() {
    float a = (1.0 - exp(-v_tau * texture(particle, gl_PointCoord).r)) * v_coverage;
    frag = vec4(v_light * a, a);
}
