#version 430
// The compute splat, 4 of 4: one work group per tile sorts the tile's entries by key (a bitonic sort
// in place, every compare-exchange putting the smaller first, so the list's padding to a power of two
// stays virtual), then each pixel blends its sprites front to back (premultiplied: C += T (J a),
// T *= 1 − a) and stops once T < 1/255. The point's rasterization, its depth test at the sprite's front
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

void main() {
    uint tile = gl_WorkGroupID.y * uint(tiles.x) + gl_WorkGroupID.x, id = gl_LocalInvocationIndex;
    uint cap = entry_capacity;
    uint begin = min(tile_offset[tile], cap), n = min(tile_offset[tile + 1u], cap) - begin;
    uint size = 1u;
    while (size < n) size <<= 1;
    for (uint k = 2u; k <= size; k <<= 1)
        for (uint j = k >> 1; j > 0u; j >>= 1) {
            for (uint t = id; t < size >> 1; t += 256u) {
                uint base = (t / j) * 2u * j, off = t % j;
                uint a = base + off, b = j == k >> 1 ? base + 2u * j - 1u - off : a + j;   // flip, then halves
                if (b < n) {
                    uvec2 ea = entries[begin + a], eb = entries[begin + b];
                    if (ea.x > eb.x) {
                        entries[begin + a] = eb;
                        entries[begin + b] = ea;
                    }
                }
            }
            memoryBarrierBuffer();
            barrier();
        }
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(px, target_size))) return;
    float depth = texelFetch(scene_depth, px, 0).r, scene = view_depth(depth, near, far);
    vec2 centre = vec2(px) + 0.5;
    vec3 C = vec3(0.0);
    vec2 D = vec2(0.0);
    float T = 1.0;
    for (uint e = n; e > 0u && T >= OPAQUE; --e) {
        uint r = entries[begin + e - 1u].y * uint(RECORD);
        ivec4 rect = floatBitsToInt(records[r + 9u]);
        if (any(lessThan(px, rect.xy)) || any(greaterThan(px, rect.zw))) continue;
        vec4 r0 = records[r];
        if (r0.w > depth) continue;                          // the point draw's depth test (<=)
        vec4 r1 = records[r + 1u], r2 = records[r + 2u], r3 = records[r + 3u];
        Sprite o = Sprite(vec4(0.0), 2.0 * r0.z, records[r + 4u], records[r + 5u].xyz, records[r + 6u].xyz,
                          records[r + 7u], records[r + 8u].xyz, r3.xyz, r2.w, r2.x, r1.xyz, r1.w, r2.y, r2.z);
        vec4 s = sprite_shade(o, (centre - r0.xy) / r0.z, scene, r3.w);
        C += T * s.rgb;
        D += T * vec2(s.a * length(o.center - camera_pos), s.a);
        T *= 1.0 - s.a;
    }
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
