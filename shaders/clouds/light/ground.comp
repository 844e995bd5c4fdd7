#version 430
// G of plugins/clouds/light/medium.py: the ground's mean sun transmittance through the clouds (float64
// reference: plugins/clouds/light/ground.py ground_sun_reference). GRID × GRID ground points whose rays
// toward the sun cross the layer's middle plane at an even grid over a set's footprint, each exp(−τ)
// with τ = extinction × the set's column sum there (bilinear, zero outside), weighted by the volume's
// edge weight (its core counts fully; the far field continues the same statistics beyond it); sets A
// and B each over their own footprint, mixed by t (so G runs on smoothly when a step arrives at a
// moved placement), summed by one group in a fixed order. Each column sum is the shape drawn
// (column.glsl typed_column, at B's placement's world point for both sets).
#include "clouds/volume/column.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = 4) writeonly buffer CloudGround { vec4 ground; };   // (G, 0, 0, 0)
const uint GRID = 64u;         // ground.py GRID
shared vec2 partial[256];

float own_sum(sampler2DArray sums, vec2 p) {       // bilinear, texel i centred at i, zero outside
    vec2 i0 = floor(p), f = p - i0;
    ivec2 i = ivec2(i0);
    float c[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 q = i + ivec2(k & 1, k >> 1);
        c[k] = any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, shape.xz)) ? 0.0 : texelFetch(sums, ivec3(q, 0), 0).r;
    }
    return mix(mix(c[0], c[1], f.x), mix(c[2], c[3], f.x), f.y);
}

void main() {
    uint i = gl_LocalInvocationIndex;
    vec2 step = vec2(shape.xz) / float(GRID);
    vec2 acc = vec2(0.0);                                           // (sum of w exp(-tau), sum of w)
    for (uint k = i; k < GRID * GRID; k += 256u) {
        vec2 v = (vec2(k % GRID, k / GRID) + 0.5) * step - 0.5;     // volume texel coordinates (centre i at i)
        float w = cloud_edge_weight((v + 0.5) / vec2(shape.xz), edge_fade);
        vec2 xz = layer_min.xz + (v + 0.5) * cell_size.xz;
        float g = mix(exp(-extinction * typed_column(own_sum(sums_a, v), xz)),
                      exp(-extinction * typed_column(own_sum(sums_b, v), xz)), t);
        acc += w * vec2(g, 1.0);
    }
    partial[i] = acc;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (i < stride) partial[i] += partial[i + stride];
        barrier();
    }
    if (i == 0u) ground = vec4(partial[0].x / max(partial[0].y, 1e-30), 0.0, 0.0, 0.0);
}
