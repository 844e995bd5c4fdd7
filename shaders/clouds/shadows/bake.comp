#version 430
// The cloud shadow map (plugins/clouds/shadows/shadow_map.py): once per frame, the sun's columns over
// the layer's middle plane (clouds/volume/column.glsl sun_columns: the volume's column × edge fade, the
// far field's × (1 − fade), per unit extinction) at the texel centres of two cascades stacked in one
// rg16f image, rows [0, N) near (its first near_size texels each way), [N, 2N) far; the near texel j
// lies at volume texel coordinate cascades[0].xy + j * cascades[0].zw, the far one at
// cascades[1].xy + cascades[1].zw * sinh(cascades[2].x * (j - cascades[2].y)) (a warped grid). Read with one fetch by clouds/shadows/shadow_map.glsl.
#include "clouds/volume/column.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rg16f) writeonly uniform image2D shadow_map;
uniform vec4 cascades[3];      // near: (first texel, step); far: (centre, K); (w / c, c), volume texels
uniform int near_size;         // the near cascade's texels per side in use: the rest hold 0
uniform vec3 bake_sun;         // unit, toward the sun (straight up while it is down)

void main() {
    ivec2 j = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(shadow_map);
    if (any(greaterThanEqual(j, size))) return;
    int n = size.x;
    int k = j.y < n ? 0 : 1;
    if (k == 0 && any(greaterThanEqual(j, ivec2(near_size)))) {
        imageStore(shadow_map, j, vec4(0.0));
        return;
    }
    vec2 i = vec2(j.x, j.y - k * n);
    vec2 v = k == 0 ? cascades[0].xy + i * cascades[0].zw
                    : cascades[1].xy + cascades[1].zw * sinh(cascades[2].x * (i - cascades[2].y));
    vec2 xz = layer_min.xz + (v + 0.5) * cell_size.xz;
    imageStore(shadow_map, j, vec4(sun_columns(v, xz, bake_sun), 0.0, 0.0));
}
