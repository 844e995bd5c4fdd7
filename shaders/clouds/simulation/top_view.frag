#version 430
// Cloud field from above: summed density (layer 0 of the density maps) of A and B mixed by t (B's
// placement fills the square, A is read a_shift cells off),
// drawn as white clouds over a blue sea, letterboxed to a square. Alpha 1: an opaque picture, no sky.
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2DArray sums_a;
layout(binding = 1) uniform sampler2DArray sums_b;
uniform float t;
uniform ivec2 a_shift;         // (x, z) cells from B's column to A's: each set shown where it was computed
uniform float full;
uniform float aspect;

void main() {
    vec2 p = (v_uv - 0.5) * vec2(aspect, 1.0) + 0.5;
    if (any(lessThan(p, vec2(0.0))) || any(greaterThan(p, vec2(1.0)))) {
        frag = vec4(0.02, 0.02, 0.03, 1.0);
        return;
    }
    vec3 uv = vec3(p.x, 1.0 - p.y, 0.0);
    vec2 n = vec2(textureSize(sums_a, 0).xy);
    vec3 uv_a = vec3((uv.xy * n + vec2(a_shift)) / n, 0.0);
    float s = mix(texture(sums_a, uv_a).r, texture(sums_b, uv).r, t);
    float c = 1.0 - exp(-s / full * 2.0);
    vec3 sea = vec3(0.05, 0.18, 0.4);
    frag = vec4(mix(sea, vec3(1.0), c), 1.0);
}
