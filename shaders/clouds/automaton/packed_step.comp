#version 430
// Packed layout, growth (eq. 2.1-2.4) + stochastic rules (eq. 2.5-2.7): one invocation per
// 32-cell word. Word w = wx + nwx * (y + ny * z); bit b of word wx is cell x = 32 * wx + b.
// State buffers: uint[3 * N], field f (0 hum, 1 act, 2 cld) at [f * N + w]; padding bits are 0.
layout(local_size_x = 64) in;

#include "lib/hash.glsl"
#include "clouds/automaton/common.glsl"

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
        uint u = atmos_hash_counter(w, u_keys[rule * uint(PRECISION_BITS) + uint(j)]);
        uint t = threshold_plane(rule, uint(j), w);
        lt |= undecided & ~u & t;
        undecided &= ~(u ^ t);
    }
    return lt & live;
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
    cld2 &= ~bernoulli_word(0u, w, cld2);
    hum2 |= bernoulli_word(1u, w, ~hum2 & valid);
    act2 |= bernoulli_word(2u, w, ~act2 & valid);

    dst[w] = hum2;
    dst[N + w] = act2;
    dst[2u * N + w] = cld2;
}
