// The sun's optical depth through the clouds from the cloud shadow map (clouds/shadows/bake.comp;
// plugins/clouds/shadows/shadow_map.py): a point is projected along the sun onto the layer's middle
// plane as clouds/volume/column.glsl sun_optical_depth does, its columns read there with one bilinear
// fetch (the near cascade where its texels in use cover the point, else the far one, its warp inverted
// with one asinh and clamped to its edge), weighted
// by the caller's extinctions and times the fraction of the layer above the point (exact: tau is that
// fraction times a function of the middle-plane point alone).
// Float64 reference: plugins/clouds/shadows/shadow_map.py lookup.
layout(binding = 9) uniform sampler2D cloud_shadow_map;
// near: (first texel's volume texel coordinate, map texels per volume texel); far: (its centre's volume
// texel coordinate, 1 / K); (c / w, c): far texel j = c + c / w asinh((v - centre) / K)
uniform vec4 shadow_cascades[3];
uniform vec4 shadow_plane;        // (layer_min.x, layer_min.z, 1 / cell.x, 1 / cell.z)
uniform vec4 shadow_heights;      // (the middle plane's y, the layer's top y, 1 / thickness, near cascade's last texel)
uniform vec2 shadow_weights;      // (volume extinction per summed cell, far field's column optical depth)
const float SHADOW_MIN_SUN_HEIGHT = 1e-4;

float cloud_shadow_tau(vec3 p, vec3 sun_dir) {
    float run = max(shadow_heights.x - p.y, 0.0) / max(sun_dir.y, SHADOW_MIN_SUN_HEIGHT);
    vec2 v = (p.xz + run * sun_dir.xz - shadow_plane.xy) * shadow_plane.zw - 0.5;
    float above = clamp((shadow_heights.y - p.y) * shadow_heights.z, 0.0, 1.0);
    float n = float(textureSize(cloud_shadow_map, 0).x);
    vec2 j = (v - shadow_cascades[0].xy) * shadow_cascades[0].zw;
    float row = 0.0;
    if (any(lessThan(j, vec2(0.0))) || any(greaterThan(j, vec2(shadow_heights.w)))) {
        vec2 d = (v - shadow_cascades[1].xy) * shadow_cascades[1].zw;
        vec2 asinh_d = sign(d) * log(abs(d) + sqrt(d * d + 1.0));      // no cancellation for d < 0
        j = clamp(shadow_cascades[2].y + shadow_cascades[2].x * asinh_d, 0.0, n - 1.0);
        row = n;
    }
    vec2 c = textureLod(cloud_shadow_map, (j + vec2(0.5, 0.5 + row)) / vec2(n, 2.0 * n), 0.0).rg;
    return dot(shadow_weights, c) * above;
}
