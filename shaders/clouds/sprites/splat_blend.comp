#version 430
// The compute splat, 4 of 4: one work group per tile sorts the tile's entries by key (a bitonic sort,
// in shared memory up to SPLAT_SHARED_SORT entries, else in place; every compare-exchange puts the
// smaller first, so the list's padding to a power of two stays virtual), then each pixel blends its
// sprites front to back (premultiplied: C += T (J a), T *= 1 − a) and stops once T < 1/255. The point's rasterization, its depth test at the sprite's front
// (<=) and the fragment (sprite.glsl sprite_shade) are the point draw's. Then onto the target: over
// it (SPLAT_OVER: the frame's colour, C + T · colour) or stored (a low-res target, alpha 1 − T); the
// distance (a·distance, a) likewise onto "cloud_distance" with SPLAT_DISTANCE.
layout(local_size_x = 16, local_size_y = 16) in;
#include "lib/frame.glsl"
#include "clouds/volume/volume.glsl"
#include "lib/view_ray.glsl"
#include "clouds/sprites/sprite.glsl"
#include "clouds/sprites/splat.glsl"
layout(binding = 5) uniform sampler2D scene_depth;
layout(binding = 0, rgba16f) uniform image2D color_image;
#if SPLAT_DISTANCE
layout(binding = 1, rg32f) uniform image2D distance_image;
#endif
const float OPAQUE = 1.0 / 255.0;       // T below this: the sprites behind are not looked at
const uint GROUP = 256u;
#ifndef SPLAT_SHARED_SORT
#define SPLAT_SHARED_SORT 2048          // lists up to this long are sorted in shared memory (16 KiB)
#endif
shared uvec2 sorting[SPLAT_SHARED_SORT];
shared ivec4 batch_rect[GROUP];         // a batch of the list, front first: what the pixels test before shading
shared vec4 batch_head[GROUP];
shared uint batch_record[GROUP];
shared uint finished;                   // pixels of the tile done (opaque, or outside the target)

// The compare-exchange pairs of stage k, step j of the bitonic sort whose every pair puts the smaller
// first: the first step of a stage pairs mirror images in blocks of k ("flip"), the others halves.
uvec2 bitonic_pair(uint t, uint k, uint j) {
    uint base = (t / j) * 2u * j, off = t % j;
    return uvec2(base + off, j == k >> 1 ? base + 2u * j - 1u - off : base + off + j);
}

void main() {
    uint tile = gl_WorkGroupID.y * uint(tiles.x) + gl_WorkGroupID.x, id = gl_LocalInvocationIndex;
    uint cap = entry_capacity;
    uint begin = min(tile_offset[tile], cap), n = min(tile_offset[tile + 1u], cap) - begin;
    if (id == 0u) tile_count[tile] = 0u;                 // the bin's cursor, back to 0 for the next frame
    // the sort (barriers in main only, in uniform control flow: n is the work group's)
    uint size = 1u;
    while (size < n) size <<= 1;
    if (n <= uint(SPLAT_SHARED_SORT)) {
        for (uint i = id; i < n; i += GROUP)
            sorting[i] = entries[begin + i];
        barrier();
        for (uint k = 2u; k <= size; k <<= 1)
            for (uint j = k >> 1; j > 0u; j >>= 1) {
                for (uint t = id; t < size >> 1; t += GROUP) {
                    uvec2 ab = bitonic_pair(t, k, j);
                    if (ab.y < n && sorting[ab.x].x > sorting[ab.y].x) {
                        uvec2 e = sorting[ab.x];
                        sorting[ab.x] = sorting[ab.y];
                        sorting[ab.y] = e;
                    }
                }
                barrier();
            }
    } else {
        for (uint k = 2u; k <= size; k <<= 1)
            for (uint j = k >> 1; j > 0u; j >>= 1) {
                for (uint t = id; t < size >> 1; t += GROUP) {
                    uvec2 ab = bitonic_pair(t, k, j);
                    if (ab.y < n) {
                        uvec2 ea = entries[begin + ab.x], eb = entries[begin + ab.y];
                        if (ea.x > eb.x) {
                            entries[begin + ab.x] = eb;
                            entries[begin + ab.y] = ea;
                        }
                    }
                }
                memoryBarrierBuffer();
                barrier();
            }
    }
    memoryBarrierBuffer();
    barrier();
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    bool inside = all(lessThan(px, target_size));
    float depth = inside ? texelFetch(scene_depth, px, 0).r : 1.0, scene = view_depth(depth, near, far);
    vec2 centre = vec2(px) + 0.5;
    vec3 C = vec3(0.0);
    vec2 D = vec2(0.0);
    float T = 1.0;
    bool done = !inside;
#if SPLAT_COUNT
    uint tested = 0u, shaded = 0u;
#endif
    // batches of GROUP entries from the front of the list: loaded together into shared memory, tested
    // by every pixel there (rectangle, depth), shaded from the record where one covers; once every
    // pixel of the tile is opaque the rest of the list is left
    for (uint end = n; end > 0u; end -= min(end, GROUP)) {
        uint count = min(end, GROUP);
        if (id == 0u) finished = 0u;
        barrier();
        if (id < count) {
            uint at = end - 1u - id, index = n <= uint(SPLAT_SHARED_SORT) ? sorting[at].y : entries[begin + at].y;
            batch_record[id] = index;
            batch_rect[id] = ivec4(records[index * uint(RECORD) + 9u]);
            batch_head[id] = record(index * uint(RECORD));
        }
        if (done) atomicAdd(finished, 1u);
        barrier();
        if (finished == GROUP) break;
        for (uint k = 0u; k < count && !done; ++k) {
            ivec4 rect = batch_rect[k];
            vec4 r0 = batch_head[k];
#if SPLAT_COUNT
            ++tested;
#endif
            if (any(lessThan(px, rect.xy)) || any(greaterThan(px, rect.zw)) || r0.w > depth) continue;  // <=: the depth test
#if SPLAT_COUNT
            ++shaded;
#endif
            uint r = batch_record[k] * uint(RECORD);
            vec4 r1 = record(r + 1u), r2 = record(r + 2u), r3 = record(r + 3u);
            Sprite o = Sprite(vec4(0.0), 2.0 * r0.z, record(r + 4u), record(r + 5u).xyz, record(r + 6u).xyz,
                              record(r + 7u), record(r + 8u).xyz, r3.xyz, r2.w, r2.x, r1.xyz, r1.w, r2.y, r2.z);
            vec4 s = sprite_shade(o, (centre - r0.xy) / r0.z, scene, r3.w);
            C += T * s.rgb;
            D += T * vec2(s.a * length(o.center - camera_pos), s.a);
            T *= 1.0 - s.a;
            done = T < OPAQUE;
        }
        barrier();
    }
#if SPLAT_COUNT
    atomicAdd(counters[TESTED], tested);
    atomicAdd(counters[SHADED], shaded);
#endif
    if (!inside) return;
#if SPLAT_OVER
    vec4 under = imageLoad(color_image, px);
    imageStore(color_image, px, vec4(C + T * under.rgb, 1.0 - T + T * under.a));
#else
    imageStore(color_image, px, vec4(C, 1.0 - T));
#endif
#if SPLAT_DISTANCE
#if SPLAT_OVER
    D += T * imageLoad(distance_image, px).rg;
#endif
    imageStore(distance_image, px, vec4(D, 0.0, 0.0));
#endif
}
