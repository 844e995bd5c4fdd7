#version 430
// Packed layout, one whole step in one dispatch: growth (eq. 2.1-2.4) + stochastic rules (eq. 2.5-2.7)
// + advection (eq. 2.8-2.10), one invocation per 32-cell word of the result. Word w = wx + nwx * (y + ny * z);
// bit b of word wx is cell x = 32 * wx + b. State buffers: uint[3 * N], field f (0 hum, 1 act, 2 cld) at
// [f * N + w]; padding bits are 0. Advection: out(x, y, z) = stepped(x - sx, y, z - sz) with the shift of
// layer y (empty from outside), so a word takes its bits from the stepped source words q and q + 1.
layout(local_size_x = 64) in;

#include "lib/hash.glsl"
#include "clouds/automaton/common.glsl"
uint k_step;                 // atmos_step_key of the step, set first in main

layout(std430, binding = 0) readonly buffer Src { uint src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };
// Threshold bit planes of per-cell probabilities, one buffer per rule: [plane * N + w].
layout(std430, binding = 2) readonly buffer PlanesExt { uint planes_ext[]; };
layout(std430, binding = 3) readonly buffer PlanesHum { uint planes_hum[]; };
layout(std430, binding = 4) readonly buffer PlanesAct { uint planes_act[]; };

uniform uint u_last_mask;    // valid bits of the last word of a row

uint threshold_plane(uint rule, uint plane, uint w) {
    if (u_mode[rule] == 1u) {
        return ((u_threshold[rule] >> plane) & 1u) != 0u ? 0xffffffffu : 0u;
    }
    uint i = plane * u_count + w;
    return rule == 0u ? planes_ext[i] : (rule == 1u ? planes_hum[i] : planes_act[i]);
}

// Bit-sliced Bernoulli: bit b set <=> U_b < T_b, for the cells in `live` (others 0). U's bits come
// MSB first, one 32-bit hash word per plane; a cell is decided at the first plane where its U bit
// and T bit differ, and the loop stops once every live cell is decided.
uint bernoulli_word(uint rule, uint w, uint live) {
    if (u_mode[rule] == 0u || live == 0u) {
        return 0u;
    }
    uint top = threshold_plane(rule, 16u, w);      // U's bit 16 is 0: T == 65536 -> always
    uint lt = top;
    uint undecided = ~top & live;
    for (int j = PRECISION_BITS - 1; j >= 0 && undecided != 0u; --j) {
        uint u = atmos_hash_counter(w, atmos_plane_key(k_step, rule, uint(j)));
        uint t = threshold_plane(rule, uint(j), w);
        lt |= undecided & ~u & t;
        undecided &= ~(u ^ t);
    }
    return lt & live;
}

// (hum, act, cld) of source word w after growth and the stochastic rules, exact on the bits in `need`
// (the random draws are made for those cells only).
uvec3 stepped(uint w, uint need) {
    uint N = u_count;
    int nwx = u_nwx;
    int wx = int(w % uint(nwx));
    uint row = w / uint(nwx);
    int y = int(row % uint(u_size.y));
    int z = int(row / uint(u_size.y));
    uint rowy = uint(nwx);
    uint rowz = uint(nwx * u_size.y);

    uint hum = src[w];
    uint act = src[N + w];
    uint cld = src[2u * N + w];

    // f_act: x +-1, +-2 within the row (bits from the adjacent words), y +-1 and y-2, z +-1, +-2.
    uint left = wx > 0 ? src[N + w - 1u] : 0u;
    uint right = wx < nwx - 1 ? src[N + w + 1u] : 0u;
    uint f = (act << 1) | (left >> 31) | (act >> 1) | (right << 31)
           | (act << 2) | (left >> 30) | (act >> 2) | (right << 30);
    if (y + 1 < u_size.y) f |= src[N + w + rowy];
    if (y >= 1) f |= src[N + w - rowy];
    if (y >= 2) f |= src[N + w - 2u * rowy];
    if (z + 1 < u_size.z) f |= src[N + w + rowz];
    if (z + 2 < u_size.z) f |= src[N + w + 2u * rowz];
    if (z >= 1) f |= src[N + w - rowz];
    if (z >= 2) f |= src[N + w - 2u * rowz];

    uint hum2 = hum & ~act;
    uint act2 = ~act & hum & f;
    uint cld2 = cld | act;

    uint valid = wx == nwx - 1 ? u_last_mask : 0xffffffffu;
    valid &= need;
    cld2 &= ~bernoulli_word(0u, w, cld2 & need);
    hum2 |= bernoulli_word(1u, w, ~hum2 & valid);
    act2 |= bernoulli_word(2u, w, ~act2 & valid);
    return uvec3(hum2, act2, cld2);
}

void main() {
    k_step = atmos_step_key(u_seed, u_step);
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
    uvec3 v = uvec3(0u);
    if (zs >= 0 && zs < u_size.z) {
        int start = 32 * wx - s.x;         // source cell of bit 0
        int q = start >> 5;                // arithmetic shift: floor division
        int r = start & 31;
        uint srow = uint(nwx) * (uint(y) + uint(u_size.y) * uint(zs));
        uvec3 lo = q >= 0 && q < nwx ? stepped(srow + uint(q), 0xffffffffu << uint(r)) : uvec3(0u);
        v = lo;
        if (r != 0) {           // bits r..31 of word q, then bits 0..r-1 of word q + 1
            uvec3 hi = q + 1 >= 0 && q + 1 < nwx ? stepped(srow + uint(q + 1), 0xffffffffu >> uint(32 - r))
                                                  : uvec3(0u);
            v = (lo >> uint(r)) | (hi << uint(32 - r));
        }
        v &= uvec3(wx == nwx - 1 ? u_last_mask : 0xffffffffu);
    }
    dst[w] = v.x;
    dst[N + w] = v.y;
    dst[2u * N + w] = v.z;
}
