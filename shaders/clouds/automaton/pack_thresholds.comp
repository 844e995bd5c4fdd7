#version 430
// Per-cell float32 probabilities [x + nx * (y + ny * z)] -> threshold bit planes [plane * N + w]
// of the packed layout (T = floor(p * 65536 + 0.5), planes 0..16). One invocation per word.
layout(local_size_x = 64) in;

#include "clouds/automaton/common.glsl"

layout(std430, binding = 6) readonly buffer Prob { float prob[]; };
layout(std430, binding = 7) writeonly buffer Planes { uint planes[]; };

void main() {
    uint w = invocation_index();
    if (w >= u_count) {
        return;
    }
    int nwx = u_nwx;
    int wx = int(w % uint(nwx));
    uint row = w / uint(nwx);
    uint t[PLANES];
    for (int j = 0; j < PLANES; ++j) t[j] = 0u;
    int x0 = 32 * wx;
    int n = min(32, u_size.x - x0);
    uint base = row * uint(u_size.x) + uint(x0);
    for (int b = 0; b < n; ++b) {
        uint T = quantize(prob[base + uint(b)]);
        for (int j = 0; j < PLANES; ++j) t[j] |= ((T >> uint(j)) & 1u) << uint(b);
    }
    for (int j = 0; j < PLANES; ++j) planes[uint(j) * u_count + w] = t[j];
}
