#version 430
// Cloud field smoothing (thesis eq. 2.11 over space, sec. 4.4): one invocation per cell of layers
// z0 + gl_GlobalInvocationID.z. Reads the automaton's cld bits straight from its state buffer
// (LAYOUT_PACKED 1: uint32 words, field 2 at u_cld_offset + wx + nwx * (y + ny * z), cell
// x = 32 * wx + b is bit b; LAYOUT_PACKED 0: one uint per cell, bit 2 = cld) and writes
// q = sum_d w(d) cld(x + d) / u_total to a FORMAT (r16f / r32f) image. Cells outside count as 0;
// q > 0 is raised to u_min_density so that it stays > 0 in the target format.
// See plugins/clouds/simulation/reference.py for the weights.
layout(local_size_x = 16, local_size_y = 4, local_size_z = 1) in;

#define MAX_RADIUS 8
#define MAX_TAPS 17                       // 2 * MAX_RADIUS + 1

layout(std430, binding = 0) readonly buffer State { uint state[]; };
layout(binding = 0, FORMAT) uniform writeonly image3D u_density;

uniform ivec3 u_size;                     // nx, ny, nz
uniform ivec3 u_radius;                   // rx, ry, rz
uniform int u_nwx;                        // words per x row (packed)
uniform uint u_cld_offset;                // index of field 2's first word (packed)
uniform int u_z0;
uniform uint u_cx[MAX_RADIUS + 1];       // x weights as steps: w(d) = sum_{k >= |d|} u_cx[k]
uniform uint u_window[MAX_RADIUS + 1];   // bits r - k .. r + k of a row (offsets |d| <= k)
uniform uint u_wy[MAX_TAPS];             // integer weights of offsets -r..r
uniform uint u_wz[MAX_TAPS];
uniform uint u_total;                     // sum of all weights (a full neighbourhood)
uniform float u_min_density;

#if LAYOUT_PACKED
uint cld_word(int w, int row) {
    return (w < 0 || w >= u_nwx) ? 0u : state[u_cld_offset + uint(w + u_nwx * row)];
}
#endif

// Bits i = 0 .. 2 rx of cells x0 + i in row (y, z); cells outside the volume read 0.
uint row_bits(int x0, int y, int z) {
    int row = y + u_size.y * z;
#if LAYOUT_PACKED
    int w = ((x0 + 32) >> 5) - 1;         // floor(x0 / 32); x0 >= -MAX_RADIUS
    int s = x0 - 32 * w;
    uint lo = cld_word(w, row);
    uint bits = s == 0 ? lo : (lo >> uint(s)) | (cld_word(w + 1, row) << uint(32 - s));
    return bits & ((1u << uint(2 * u_radius.x + 1)) - 1u);   // padding bits past nx are 0
#else
    uint bits = 0u;
    for (int i = 0; i <= 2 * u_radius.x; ++i) {
        int x = x0 + i;
        if (x >= 0 && x < u_size.x) {
            bits |= ((state[uint(x + u_size.x * row)] >> 2u) & 1u) << uint(i);
        }
    }
    return bits;
#endif
}

void main() {
    ivec3 cell = ivec3(gl_GlobalInvocationID.xy, int(gl_GlobalInvocationID.z) + u_z0);
    if (any(greaterThanEqual(cell, u_size))) return;
    uint sum = 0u;
    for (int dz = -u_radius.z; dz <= u_radius.z; ++dz) {
        int z = cell.z + dz;
        if (z < 0 || z >= u_size.z) continue;
        for (int dy = -u_radius.y; dy <= u_radius.y; ++dy) {
            int y = cell.y + dy;
            if (y < 0 || y >= u_size.y) continue;
            uint bits = row_bits(cell.x - u_radius.x, y, z);
            uint row = 0u;                // sum_d wx(d) cld(x + d) from r + 1 popcounts
            for (int k = 0; k <= u_radius.x; ++k) {
                row += u_cx[k] * uint(bitCount(bits & u_window[k]));
            }
            sum += row * u_wy[dy + u_radius.y] * u_wz[dz + u_radius.z];
        }
    }
    float q = 0.0;
    if (sum == u_total) {
        q = 1.0;
    } else if (sum > 0u) {
        q = max(float(sum) / float(u_total), u_min_density);
    }
    imageStore(u_density, cell, vec4(q));
}
