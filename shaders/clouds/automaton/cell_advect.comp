#version 430
// Cell layout, advection (eq. 2.8-2.10): out(x, y, z) = in(x - sx, y, z - sz), empty from outside.
layout(local_size_x = 64) in;

#include "clouds/automaton/common.glsl"

layout(std430, binding = 0) readonly buffer Src { uint src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };

void main() {
    uint c = invocation_index();
    if (c >= u_count) {
        return;
    }
    int x = int(c % uint(u_size.x));
    uint row = c / uint(u_size.x);
    int y = int(row % uint(u_size.y));
    int z = int(row / uint(u_size.y));
    ivec2 s = u_shifts[y];
    int xs = x - s.x;
    int zs = z - s.y;
    uint v = 0u;
    if (xs >= 0 && xs < u_size.x && zs >= 0 && zs < u_size.z) {
        v = src[uint(xs) + uint(u_size.x) * (uint(y) + uint(u_size.y) * uint(zs))];
    }
    dst[c] = v;
}
