#version 430
// The compute splat, 3 of 4: every drawn sprite writes (key, record) into each tile it covers, at the
// tile's offset plus a slot taken from its cursor (in no order: the blend sorts). Entries past the
// list's capacity are dropped (the pass grows the list from the total the scan wrote).
layout(local_size_x = 64) in;
#include "clouds/sprites/splat.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    uint drawn = min(tile_offset[uint(tiles.x * tiles.y) + 1u], uint(records.length()) / uint(RECORD));
    if (i >= drawn) return;                              // the sprites drawn (the scan's total), as recorded
    uint r = i * uint(RECORD);
    uint key = records[r + 6u].w;
    ivec4 rect = ivec4(records[r + 9u]);
    ivec2 t0 = rect.xy / TILE, t1 = rect.zw / TILE;
    for (int y = t0.y; y <= t1.y; ++y)
        for (int x = t0.x; x <= t1.x; ++x) {
            int tile = y * tiles.x + x;
            uint e = tile_offset[tile] + atomicAdd(tile_count[tile], 1u);
            if (e < entry_capacity)
                entries[e] = uvec2(key, i);
        }
}
