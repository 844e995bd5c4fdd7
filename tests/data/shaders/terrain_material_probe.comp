#version 430
// terrain_albedo (terrain/material.glsl) at given points: In holds per point (p.xyz, footprint) and
// (n.xyz, 0); Out gets the albedo (rgb, 0). tests/test_terrain.py compares it with the float64 twin.
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
#include "terrain/material.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { vec4 v_in[]; };
layout(std430, binding = 1) writeonly buffer Out { vec4 v_out[]; };
uniform uint count;
uniform float relief;
uniform float snowline;
uniform float rock_slope;

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= count) return;
    vec4 a = v_in[2u * k], b = v_in[2u * k + 1u];
    v_out[k] = vec4(terrain_albedo(a.xyz, b.xyz, a.w, relief, snowline, rock_slope), 0.0);
}
