#version 430
// The simulation's cover for the far field (float64 reference: atmos/plugins/cloud_far_field/cover.py
// volume_cover): Σ w·[sum > threshold] / Σ w over the columns of mix(A, B, t) (A at c + a_shift,
// empty past its edge), w the volume's edge weight at the column's centre. One work group of 256.
#include "clouds/edge.glsl"
layout(local_size_x = 256) in;
layout(binding = 0) uniform sampler2DArray sums_a;
layout(binding = 1) uniform sampler2DArray sums_b;
layout(std430, binding = 0) writeonly buffer Cover { float cover; };
uniform float t;
uniform ivec2 a_shift;
uniform float threshold;
uniform float edge_fade;
shared vec2 partial[256];

void main() {
    ivec2 n = textureSize(sums_b, 0).xy;
    uint i = gl_LocalInvocationIndex;
    vec2 acc = vec2(0.0);
    for (int c = int(i); c < n.x * n.y; c += 256) {
        ivec2 p = ivec2(c % n.x, c / n.x);
        ivec2 pa = p + a_shift;
        float a = any(lessThan(pa, ivec2(0))) || any(greaterThanEqual(pa, n)) ? 0.0 : texelFetch(sums_a, ivec3(pa, 0), 0).r;
        float s = mix(a, texelFetch(sums_b, ivec3(p, 0), 0).r, t);
        float w = cloud_edge_weight((vec2(p) + 0.5) / vec2(n), edge_fade);
        acc += vec2(s > threshold ? w : 0.0, w);
    }
    partial[i] = acc;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (i < stride) partial[i] += partial[i + stride];
        barrier();
    }
    if (i == 0u) cover = partial[0].x / max(partial[0].y, 1e-30);
}
