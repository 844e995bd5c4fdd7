#version 430
// The compute splat, 1 of 4: one invocation per block of a segment (sprite.glsl sprite_setup, as the
// point draw's vertex). A drawn sprite (in front, inside the clip volume, covering a pixel) appends its
// record and counts itself in every tile its point square covers. The square covers the pixels whose
// centres lie inside it, as a point's rasterization does; unlike a point, a sprite whose centre is off
// screen still draws its part on screen (no pop at the edges of the view).
layout(local_size_x = 64) in;
#define CLOUD_EXACT_FILTER
#include "lib/frame.glsl"
#include "clouds/volume/volume.glsl"
#include "clouds/sprites/sprite.glsl"
#include "clouds/sprites/splat.glsl"
layout(std430, binding = 5) readonly buffer SplatSegments { ivec4 segments[]; };
uniform int segment_count;
uniform int unit_blocks;      // the most blocks a unit has: the key's stride
uniform uint record_capacity;

void main() {
    int segment = int(gl_GlobalInvocationID.y + gl_GlobalInvocationID.z * gl_NumWorkGroups.y);
    int block = int(gl_GlobalInvocationID.x);
    if (segment >= segment_count || block >= unit_blocks) return;
    ivec4 seg = segments[segment];
    int level = seg.w & 3;
    ivec2 span = 1 + ((ivec2(seg.w) >> ivec2(2, 3)) & 1);
    if (block >= ((group_size.x * span.x) >> level) * ((group_size.y * span.y) >> level)) return;
    Sprite o;
    if (!sprite_setup(seg, block, o)) return;
    vec4 p = o.position;
    if (!(p.w > 0.0) || p.z > p.w || p.z < -p.w || !(o.coverage > 0.0)) return;
#if SPLAT_CLIP_CENTRES
    if (abs(p.x) > p.w || abs(p.y) > p.w) return;     // as a point is clipped (only to compare with the point draw)
#endif
    vec2 c = (p.xy / p.w * 0.5 + 0.5) * vec2(target_size);
    float half_side = 0.5 * o.point_size;
    ivec2 lo = max(ivec2(ceil(c - half_side - 0.5)), ivec2(0));
    ivec2 hi = min(ivec2(ceil(c + half_side - 0.5)) - 1, target_size - 1);
    if (any(greaterThan(lo, hi))) return;
    uint i = atomicAdd(counters[SPRITES], 1u);
    if (i >= record_capacity) return;
    uint r = i * uint(RECORD);
    put_record(r, vec4(c, half_side, p.z / p.w * 0.5 + 0.5));
    put_record(r + 1u, vec4(o.conic, o.falloff));
    put_record(r + 2u, vec4(o.tau, o.coverage, o.stretch, o.radius));
    put_record(r + 3u, vec4(o.center, p.w));
    put_record(r + 4u, o.octaves);
    put_record(r + 5u, vec4(o.slope, 0.0));
    records[r + 6u] = uvec4(floatBitsToUint(o.ambient), uint(segment * unit_blocks + block));   // w: the key
    put_record(r + 7u, o.field);
    put_record(r + 8u, vec4(o.sun, 0.0));
    records[r + 9u] = uvec4(ivec4(lo, hi));
#if SPLAT_COUNT
    atomicAdd(counters[COVERED], uint((hi.x - lo.x + 1) * (hi.y - lo.y + 1)));
#endif
    ivec2 t0 = lo / TILE, t1 = hi / TILE;
    for (int y = t0.y; y <= t1.y; ++y)
        for (int x = t0.x; x <= t1.x; ++x)
            atomicAdd(tile_count[y * tiles.x + x], 1u);
}
