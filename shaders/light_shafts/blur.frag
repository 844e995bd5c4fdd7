#version 430
// Light shafts, 2/3: radial blur of the mask toward the sun (GPU Gems 3, ch. 13): `samples` taps at
// uv - i * step (i = 1..samples), step = (uv - sun_uv) * density / samples, tap i weighing
// weight * decay^(i-1); bilinear with zero outside the mask. plugins/light_shafts/reference.py: radial_blur.
// The sum is at most HDR_MAX (lib/hdr_max.glsl): it is blended onto the float16 colour.
out vec4 frag;
layout(binding = 0) uniform sampler2D mask;
uniform vec2 sun_uv;
uniform int samples;
uniform float density;
uniform float decay;
uniform float scale;       // weight x exposure x the fades, at most float32's largest (settings.py: blur_scale)
#include "lib/hdr_max.glsl"

vec3 tap(ivec2 i, ivec2 n) {
    if (any(lessThan(i, ivec2(0))) || any(greaterThanEqual(i, n))) return vec3(0.0);
    return texelFetch(mask, i, 0).rgb;
}

vec3 bilinear(vec2 uv, ivec2 n) {
    vec2 p = uv * vec2(n) - 0.5;
    if (any(lessThanEqual(p, vec2(-1.0))) || any(greaterThanEqual(p, vec2(n)))) return vec3(0.0);
    vec2 i0 = floor(p);
    vec2 f = p - i0;
    ivec2 i = ivec2(i0);
    return mix(mix(tap(i, n), tap(i + ivec2(1, 0), n), f.x), mix(tap(i + ivec2(0, 1), n), tap(i + ivec2(1, 1), n), f.x), f.y);
}

void main() {
    ivec2 n = textureSize(mask, 0);
    vec2 uv = gl_FragCoord.xy / vec2(n);
    vec2 step = (uv - sun_uv) * (density / float(samples));
    vec3 sum = vec3(0.0);
    float falloff = 1.0;
    for (int i = 1; i <= samples; ++i) {
        sum += bilinear(uv - float(i) * step, n) * falloff;
        falloff *= decay;
    }
    // sum: finite (taps <= 65504, at most 256 of them), scale finite: the product is never NaN, and
    // min() turns its float32 overflow (+inf) into HDR_MAX
    frag = vec4(min(sum * scale, vec3(HDR_MAX)), 0.0);
}
