#version 430
// FXAA, the console variant (Lottes 2009): the luma of the four diagonal neighbours gives the edge's
// direction; two taps along it (and two more, farther) blur across the stair steps, and the wider blur
// is kept unless its luma leaves the neighbourhood's range. Luma of HDR colour compressed l / (1 + l).
// Taps are bilinear by hand from exact texel fetches (hardware filtering weights are 8-bit on some
// GPUs); plugins/antialias/reference.py is the float64 reference. One compute invocation per pixel, from
// a copy of the colour into the colour.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D source;   // the frame's colour before this pass (a copy)
layout(binding = 0, rgba16f) writeonly uniform image2D color_image;
uniform float reduce_min;
uniform float reduce_mul;
uniform float span_max;

float luma(vec3 c) {
    float l = dot(max(c, vec3(0.0)), vec3(0.299, 0.587, 0.114));
    return l / (1.0 + l);
}

vec4 fetch(ivec2 p) {
    return texelFetch(source, clamp(p, ivec2(0), textureSize(source, 0) - 1), 0);
}

vec4 bilinear(vec2 p) {                          // p in pixels; texel centres at +0.5
    vec2 q = p - 0.5;
    ivec2 i = ivec2(floor(q));
    vec2 f = q - floor(q);
    return mix(mix(fetch(i), fetch(i + ivec2(1, 0)), f.x), mix(fetch(i + ivec2(0, 1)), fetch(i + ivec2(1, 1)), f.x), f.y);
}

void main() {
    ivec2 c = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(c, imageSize(color_image)))) return;
    vec2 p = vec2(c) + 0.5;
    vec4 m = fetch(c);
    float l_nw = luma(fetch(c + ivec2(-1, 1)).rgb), l_ne = luma(fetch(c + ivec2(1, 1)).rgb);
    float l_sw = luma(fetch(c + ivec2(-1, -1)).rgb), l_se = luma(fetch(c + ivec2(1, -1)).rgb);
    float l_m = luma(m.rgb);
    vec2 dir = vec2(-((l_nw + l_ne) - (l_sw + l_se)), (l_nw + l_sw) - (l_ne + l_se));
    float reduce = max((l_nw + l_ne + l_sw + l_se) * 0.25 * reduce_mul, reduce_min);
    float scale = 1.0 / (min(abs(dir.x), abs(dir.y)) + reduce);
    dir = clamp(dir * scale, vec2(-span_max), vec2(span_max));
    vec3 a = 0.5 * (bilinear(p + dir * (1.0 / 3.0 - 0.5)).rgb + bilinear(p + dir * (2.0 / 3.0 - 0.5)).rgb);
    vec3 b = 0.5 * a + 0.25 * (bilinear(p - 0.5 * dir).rgb + bilinear(p + 0.5 * dir).rgb);
    float l_min = min(l_m, min(min(l_nw, l_ne), min(l_sw, l_se)));
    float l_max = max(l_m, max(max(l_nw, l_ne), max(l_sw, l_se)));
    float l_b = luma(b);
    imageStore(color_image, c, vec4(l_b < l_min || l_b > l_max ? a : b, m.a));   // alpha: the sky occlusion, kept
}
