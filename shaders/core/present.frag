#version 430
// Present: HDR scene colour -> display. Exposure, ACES-fitted tone curve, sRGB encoding, then a
// triangular (TPDF) dither of ±1 step of the 8-bit output so gradients do not band, rounded to the
// nearest 8-bit level here; float64 reference: atmos/render_core.py (present_levels).
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D hdr;
uniform float exposure;
uniform float dither;       // 1/255 (one 8-bit step) or 0: none
#include "lib/hash.glsl"

vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// Two independent uniforms in [0, 1) per pixel and channel, summed: triangular on (-1, 1).
vec3 tpdf(uvec2 pixel) {
    uint h = atmos_lowbias32(pixel.x * 0x9e3779b9u ^ atmos_lowbias32(pixel.y + 0x2f6b4d5du));
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 2; i++) {
        uint a = atmos_lowbias32(h + uint(2 * i));
        uint b = atmos_lowbias32(h + uint(2 * i + 1));
        sum += vec3(float(a & 0xffffu), float(a >> 16), float(b & 0xffffu)) / 65536.0;
    }
    return sum - 1.0;
}

void main() {
    vec3 c = texture(hdr, v_uv).rgb * exposure;
    c = pow(aces(max(c, vec3(0.0))), vec3(1.0 / 2.2)) + dither * tpdf(uvec2(gl_FragCoord.xy));
    // An exact level k/255: the framebuffer's own float -> 8-bit conversion need not round to nearest
    // (GL lets it pick either neighbour; NVIDIA's rounds values up to 1/16 step above a tie down,
    // a bias of the mean), but every conversion keeps a level.
    frag = vec4(clamp(floor(c * 255.0 + 0.5), 0.0, 255.0) / 255.0, 1.0);
}
