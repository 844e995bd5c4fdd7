#version 430
// Cell layout (the thesis's, one element per cell), one whole step in one dispatch: growth + stochastic
// rules of the source cell (x - sx, y, z - sz) with the shift of layer y (advection, empty from outside).
// State buffers:
// uint per cell c = x + nx * (y + ny * z), bit 0 hum, bit 1 act, bit 2 cld. Same random numbers
// as the packed layout: cell x of row (y, z) takes bit x % 32 of the word hashes of word
// x / 32 + nwx * (y + ny * z), so both layouts give identical results.
layout(local_size_x = 64) in;

#include "lib/hash.glsl"
#include "clouds/automaton/common.glsl"
uint k_step;                 // atmos_step_key of the step, set first in main

layout(std430, binding = 0) readonly buffer Src { uint src[]; };
layout(std430, binding = 1) writeonly buffer Dst { uint dst[]; };
// Per-cell float32 probabilities [c], one buffer per rule (mode 2).
layout(std430, binding = 2) readonly buffer ProbExt { float prob_ext[]; };
layout(std430, binding = 3) readonly buffer ProbHum { float prob_hum[]; };
layout(std430, binding = 4) readonly buffer ProbAct { float prob_act[]; };

bool act_at(int x, int y, int z) {
    if (x < 0 || x >= u_size.x || y < 0 || y >= u_size.y || z < 0 || z >= u_size.z) {
        return false;
    }
    return (src[uint(x) + uint(u_size.x) * (uint(y) + uint(u_size.y) * uint(z))] & 2u) != 0u;
}

// U < T with U's bits MSB first from the word hashes; stops at the first differing bit.
bool bernoulli_cell(uint rule, uint c, uint w, uint b) {
    uint T;
    if (u_mode[rule] == 1u) {
        T = u_threshold[rule];
    } else {
        float p = rule == 0u ? prob_ext[c] : (rule == 1u ? prob_hum[c] : prob_act[c]);
        T = quantize(p);
    }
    if (T >= 65536u) return true;
    if (T == 0u) return false;
    for (int j = PRECISION_BITS - 1; j >= 0; --j) {
        uint u = (atmos_hash_counter(w, atmos_plane_key(k_step, rule, uint(j))) >> b) & 1u;
        uint t = (T >> uint(j)) & 1u;
        if (u != t) return u < t;
    }
    return false;
}

// The state bits of cell (x, y, z) after growth and the stochastic rules.
uint stepped(int x, int y, int z) {
    uint row = uint(y) + uint(u_size.y) * uint(z);
    uint c = uint(x) + uint(u_size.x) * row;
    uint s = src[c];
    bool hum = (s & 1u) != 0u;
    bool act = (s & 2u) != 0u;
    bool cld = (s & 4u) != 0u;
    // Neighbourhood of eq. 2.4 (k -> y): +-1 on x, y, z; +-2 on x and z; -2 on y.
    bool f = act_at(x + 1, y, z) || act_at(x - 1, y, z) || act_at(x, y + 1, z) || act_at(x, y - 1, z)
          || act_at(x, y, z + 1) || act_at(x, y, z - 1) || act_at(x + 2, y, z) || act_at(x - 2, y, z)
          || act_at(x, y, z + 2) || act_at(x, y, z - 2) || act_at(x, y - 2, z);
    bool hum2 = hum && !act;
    bool act2 = !act && hum && f;
    bool cld2 = cld || act;

    uint w = uint(x >> 5) + uint(u_nwx) * row;
    uint b = uint(x & 31);
    if (cld2 && u_mode.x != 0u && bernoulli_cell(0u, c, w, b)) cld2 = false;
    if (!hum2 && u_mode.y != 0u && bernoulli_cell(1u, c, w, b)) hum2 = true;
    if (!act2 && u_mode.z != 0u && bernoulli_cell(2u, c, w, b)) act2 = true;
    return (hum2 ? 1u : 0u) | (act2 ? 2u : 0u) | (cld2 ? 4u : 0u);
}

void main() {
    k_step = atmos_step_key(u_seed, u_step);
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
    dst[c] = xs >= 0 && xs < u_size.x && zs >= 0 && zs < u_size.z ? stepped(xs, y, zs) : 0u;
}
