#version 430
// Packed layout, advection (eq. 2.8-2.10): out(x, y, z) = in(x - sx, y, z - sz) with the shift of
// layer y; cells from outside the volume are empty. One invocation per word, all three fields.
layout(local_size_x = 64) in;

#include "clouds/automaton/common.glsl"

layout(std430, binding = 0) readonly buffer Src { uint src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };

uniform uint u_last_mask;

uint fetch(uint base, int q) {
    return (q >= 0 && q < u_nwx) ? src[base + uint(q)] : 0u;
}

void main() {
    uint w = invocation_index();
    if (w >= u_count) {
        return;
    }
    uint N = u_count;
    int nwx = u_nwx;
    int wx = int(w % uint(nwx));
    uint row = w / uint(nwx);
    int y = int(row % uint(u_size.y));
    int z = int(row / uint(u_size.y));
    ivec2 s = u_shifts[y];                 // clamped on the CPU to |s| <= n
    int zs = z - s.y;
    if (zs < 0 || zs >= u_size.z) {
        dst[w] = 0u;
        dst[N + w] = 0u;
        dst[2u * N + w] = 0u;
        return;
    }
    uint valid = wx == nwx - 1 ? u_last_mask : 0xffffffffu;
    int start = 32 * wx - s.x;             // source cell of bit 0
    int q = start >> 5;                    // arithmetic shift: floor division
    int r = start & 31;
    uint srow = uint(nwx) * (uint(y) + uint(u_size.y) * uint(zs));
    for (uint field = 0u; field < 3u; ++field) {
        uint base = field * N + srow;
        uint lo = fetch(base, q);
        uint v = r == 0 ? lo : (lo >> uint(r)) | (fetch(base, q + 1) << uint(32 - r));
        dst[field * N + w] = v & valid;
    }
}
