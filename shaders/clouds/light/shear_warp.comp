#version 430
// The true-path shear-warp as one dispatch of sun-aligned columns (plugins/clouds/light/shear_warp.py;
// float64 twin: reference.shear_warp_scheme). Column Q starts on the light-side slice at lateral Q and lies
// at Q - k v on the k-th slice (v: the lateral step toward the sun per slice). Along its own straight ray it
// adds sigma * L * (t1 - t0) * (rho(t0) + rho(t1)) / 2 over the part [t0, t1] of the step toward the slice
// before that lies inside the box (half a step on the light-side slice): no interpolation between columns.
// The warp: cell c of slice k takes the depth of the 4x4 columns around c + k v (Catmull-Rom, limited to
// the four nearest), except where that cannot work (bends(): listed in Band for shear_warp_rays.comp, which
// marches those cells). A group marches TILE x TILE columns, shares BATCH slices' depths in shared memory
// at a time (one barrier per batch) and writes the cells of its OWN x OWN inner columns; the depths carry
// over to the next run's slices.
layout(local_size_x = 16, local_size_y = 16) in;
#include "clouds/light/shear_warp.glsl"
#include "lib/catmull_rom.glsl"

const int TILE = 16;
const int OWN = TILE - 3;      // taps -1 .. +2 around the owner's column
const int BATCH = 8;           // slices per barrier

layout(rg32f, binding = 0) uniform readonly image2D carry_in;   // per column after the last run: depth, rho (< 0: none)
layout(rg32f, binding = 1) uniform writeonly image2D carry_out;

layout(std430, binding = 0) buffer Band {     // the cells that march their own ray, appended
    uvec4 band_args;           // dispatch of shear_warp_rays.comp (groups of 64, 1, 1); cells listed
    uvec2 band[];              // (x | y << 16, k)
};

shared float depths[2][BATCH][TILE][TILE];

void main() {
    ivec2 n = lateral_size();
    ivec2 l = ivec2(gl_LocalInvocationID.xy);
    ivec2 slot = ivec2(gl_WorkGroupID.xy) * OWN + l - 1;       // the column's place in the carry images
    ivec2 column = columns.xy + slot;
    bool owner = all(greaterThanEqual(l, ivec2(1))) && all(lessThanEqual(l, ivec2(OWN)));
    vec2 v = light.xy;
    float depth = 0.0;
    float rho_before = -1.0;       // rho where this column crossed the slice before (t = 1 of this step); < 0: none
    if (columns.z > 0 && all(greaterThanEqual(slot, ivec2(0))) && all(lessThan(slot, imageSize(carry_in)))) {
        vec2 carried = imageLoad(carry_in, slot).rg;
        depth = carried.x;
        rho_before = carried.y;
    }
    vec2 group_low = vec2(columns.xy + ivec2(gl_WorkGroupID.xy) * OWN - 1);     // the group's first column
    for (int start = columns.z; start < columns.w; start += BATCH) {
        int end = min(start + BATCH, columns.w);
        // the whole group outside the box on these slices (and the step before): nothing to add, no cell to
        // write; the same for every invocation of the group, so the barrier is skipped by all of them. The
        // group's columns move in a straight line through the convex box, so the batches it works on are
        // consecutive and the two shared buffers still alternate between barriers.
        vec2 a = group_low - float(max(start - 1, 0)) * v, b = group_low - float(end - 1) * v;
        vec2 lo = min(a, b), hi = max(a, b) + float(TILE - 1);
        if (any(lessThan(hi, vec2(-1.5))) || any(greaterThan(lo, vec2(n) + 0.5))) {
            rho_before = -1.0;
            continue;
        }
        int parity = (start / BATCH) & 1;          // two buffers: the next batch writes the other one
        for (int k = start; k < end; ++k) {
            vec2 p = vec2(column) - float(k) * v;
            vec2 part = inside_part(k, p, n);
            float rho_here = -1.0;
            if (part.y > part.x) {
                float r0 = rho_at(k, p, part.x);
                if (part.x == 0.0) rho_here = r0;
                float r1 = part.y == 1.0 && rho_before >= 0.0 ? rho_before : rho_at(k, p, part.y);
                depth = min(depth + step_depth(part, r0, r1), TAU_MAX);
            }
            rho_before = rho_here;
            depths[parity][k - start][l.y][l.x] = depth;
        }
        memoryBarrierShared();
        barrier();
        if (owner) {
            for (int k = start; k < end; ++k) {
                vec2 kv = float(k) * v;
                ivec2 shift = ivec2(floor(kv));
                ivec2 cell = column - shift;
                vec2 f = kv - vec2(shift);
                if (any(lessThan(cell, ivec2(0))) || any(greaterThanEqual(cell, n))) continue;
                if (bends(k, cell, f, n)) {
                    uint index = atomicAdd(band_args.w, 1u);
                    if (index < uint(band.length())) {
                        band[index] = uvec2(uint(cell.x) | (uint(cell.y) << 16), uint(k));
                        atomicMax(band_args.x, index / 64u + 1u);
                    }
                    continue;
                }
                vec4 wb = catmull_rom_weights(f.x), wc = catmull_rom_weights(f.y);
                float sum = 0.0, low = 1e38, high = -1e38;
                for (int j = 0; j < 4; ++j) {
                    for (int i = 0; i < 4; ++i) {
                        float tap = depths[parity][k - start][l.y + j - 1][l.x + i - 1];
                        sum += wb[i] * wc[j] * tap;
                        if ((i == 1 || i == 2) && (j == 1 || j == 2)) { low = min(low, tap); high = max(high, tap); }
                    }
                }
                float value = clamp(sum, low, high);
                imageStore(result, ivec3(grid_point(float(slice_of(k)), vec2(cell))), vec4(exp(-max(value, 0.0))));
            }
        }
    }
    if (owner && columns.w > columns.z) imageStore(carry_out, slot, vec4(depth, rho_before, 0.0, 0.0));
}
