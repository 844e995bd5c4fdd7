#version 430
// The cloud shadow map against the column sums it replaces, at given points (plugins/clouds/shadows/probe.py):
// per point (sun_optical_depth, cloud_shadow_tau), both with the same extinctions.
#include "clouds/volume/column.glsl"
#include "clouds/shadows/shadow_map.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 1) readonly buffer Points { vec4 points[]; };
layout(std430, binding = 2) writeonly buffer Taus { vec2 taus[]; };
uniform vec3 probe_sun;
uniform int count;

void main() {
    int i = int(gl_GlobalInvocationID.x);
    if (i >= count) return;
    vec3 p = points[i].xyz;
    taus[i] = vec2(sun_optical_depth(p, probe_sun), cloud_shadow_tau(p, probe_sun));
}
