#version 430
// Present: HDR scene colour -> display. Exposure, ACES-fitted tone curve, sRGB encoding, then a
// triangular (TPDF) dither of ±1 step of the 8-bit output so gradients do not band, rounded to the
// nearest 8-bit level here; one invocation per pixel stores it into the screen image (rgba8, copied to
// the screen by the present pass); float64 reference: atmos/render_core.py (present_levels).
// PRESENT_FORMAT: the image's format, rgba8 (the screen's bytes) or rgba32f (the values stored, read back).
// CAMERA 1: the exposure (and the bloom's weight) come from the physical camera's buffer, written on the
// GPU this frame (plugins/physical_camera), not from the uniform; BLOOM 1: the colour is first mixed with
// the bloom (half size, upsampled by lib/upsample2x.glsl) by that weight.
#ifndef PRESENT_FORMAT
#define PRESENT_FORMAT rgba8
#endif
#ifndef CAMERA
#define CAMERA 0
#endif
#ifndef BLOOM
#define BLOOM 0
#endif
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D hdr;
layout(binding = 0, PRESENT_FORMAT) uniform writeonly image2D screen_image;
#if CAMERA
#include "lib/camera.glsl"
#else
uniform float exposure;
#endif
#if BLOOM
#include "lib/upsample2x.glsl"
layout(binding = 1) uniform sampler2D bloom_image;
#endif
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
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSize(screen_image)))) return;
    vec3 c = texelFetch(hdr, pixel, 0).rgb;
#if BLOOM
    c = mix(c, upsample2x(bloom_image, pixel), bloom);
#endif
    c *= exposure;
    c = pow(aces(max(c, vec3(0.0))), vec3(1.0 / 2.2)) + dither * tpdf(uvec2(pixel));
    // An exact level k/255: the conversion to 8 bits need not round to nearest (GL lets it pick either
    // neighbour; NVIDIA's framebuffer rounds values up to 1/16 step above a tie down, a bias of the
    // mean), but every conversion keeps a level.
    imageStore(screen_image, pixel, vec4(clamp(floor(c * 255.0 + 0.5), 0.0, 255.0) / 255.0, 1.0));
}
