// The cloud type's vertical shape of the drawn density (Nubis), what and why:
// plugins/clouds/volume/shape.py (the float64 twins type_profile and type_density, the constants).
// type_density(m, h, t): a column of mean density m over the layer, at height fraction h, of type t
// (0 stratus, 0.5 cumulus, 1 congestus), t from cloud_type_at (a uniform, or a map over the ground).
// cloud_type < 0: the simulation's own vertical shape (march.glsl shaped_density applies it).
#ifndef SHAPE_GLSL_INCLUDED
#define SHAPE_GLSL_INCLUDED

uniform float cloud_type;      // RaymarchCloudSettings.cloud_type; -1: None (and no map)
uniform int type_mapped;       // 1: cloud_type_map gives the type (RaymarchCloudSettings.type_map)
uniform vec4 type_map_box;     // the map's world corner (x, z) and 1 / its size (x, z), metres
layout(binding = 26) uniform sampler2D cloud_type_map;   // CloudTypeMap.types: R32F, linear, clamped to edge
uniform float march_top;       // how high the clouds reach, in layer heights (shape.py march_top: > 1 with towers)

const vec3 TYPE_PROFILES[3] = vec3[3](vec3(0.05, 0.10, 0.28), vec3(0.08, 0.20, 0.70), vec3(0.06, 0.20, 2.50));
const float COLUMN_FULL = 0.35;
const float ANVIL = 0.5;
const vec2 ANVIL_FROM = vec2(0.7, 0.95);
const int TYPE_SUN_STEPS = 2;   // march.glsl sun_transmittance: more sun steps in place of the shading volume

// The type at world point xz: the map's (bilinear between texel centres, the edge beyond) or cloud_type.
float cloud_type_at(vec2 xz) {
    if (type_mapped == 0) return cloud_type;
    return textureLod(cloud_type_map, (xz - type_map_box.xy) * type_map_box.zw, 0.0).r;
}

float type_ramp(float x, float a, float b) {
    return clamp((x - a) / (b - a), 0.0, 1.0);
}

// (rise end, fall start, fall end) of type t; the fall end (the type's top) passes 1 past cumulus: towers.
vec3 type_breakpoints(float t) {
    t = clamp(t, 0.0, 1.0);
    return TYPE_PROFILES[0] + (TYPE_PROFILES[1] - TYPE_PROFILES[0]) * clamp(2.0 * t, 0.0, 1.0)
         + (TYPE_PROFILES[2] - TYPE_PROFILES[1]) * clamp(2.0 * t - 1.0, 0.0, 1.0);
}

float type_profile(float h, float t) {
    if (h < 0.0) return 0.0;
    vec3 b = type_breakpoints(t);
    float x = type_ramp(h, b.y, b.z);
    return type_ramp(h, 0.0, b.x) * (1.0 - x * x);
}

float type_density(float m, float h, float t) {
    float c = clamp(m / COLUMN_FULL, 0.0, 1.0);
    if (c <= 0.0) return 0.0;
    float top = type_breakpoints(t).z;
    c = pow(c, 1.0 - ANVIL * clamp(2.0 * t - 1.0, 0.0, 1.0) * type_ramp(h, ANVIL_FROM.x * top, ANVIL_FROM.y * top));
    return clamp(type_profile(h, t) - (1.0 - c), 0.0, c);    // c remap(P, 1 - c, 1, 0, 1)
}
#endif
