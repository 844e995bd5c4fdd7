#version 430
// The compute splat, 2 of 4: the tiles' exclusive prefix sums of their counts (one work group, each
// invocation a run of tiles), then the totals (entries, sprites drawn); every count set back to 0 as
// the bin's cursor, and the sprites' counter for the next frame.
layout(local_size_x = 1024) in;
#include "clouds/sprites/splat.glsl"
shared uint sums[1024];

void main() {
    uint n = uint(tiles.x * tiles.y), id = gl_LocalInvocationID.x;
    uint run = (n + 1023u) / 1024u, first = min(id * run, n), last = min(first + run, n);
    uint own = 0u;
    for (uint t = first; t < last; ++t)
        own += tile_count[t];
    sums[id] = own;
    barrier();
    for (uint step = 1u; step < 1024u; step <<= 1) {          // Hillis-Steele inclusive scan
        uint add = id >= step ? sums[id - step] : 0u;
        barrier();
        sums[id] += add;
        barrier();
    }
    uint at = sums[id] - own;
    for (uint t = first; t < last; ++t) {
        uint count = tile_count[t];
        tile_offset[t] = at;
        tile_count[t] = 0u;
        at += count;
    }
    if (id == 1023u) {
        tile_offset[n] = sums[id];
        tile_offset[n + 1u] = counters[SPRITES];
        counters[SPRITES] = 0u;                      // for the next frame's setup
    }
}
