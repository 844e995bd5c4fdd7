#version 430
// Test probe: detail_density(d, p, probe_footprint) at the point p = texel.xyz (m) with d = texel.w of unit 0's input.
#include "clouds/raymarch/detail.glsl"

layout(binding = 0) uniform sampler2D probe_points;
uniform float probe_footprint;     // the pixel's width (m) at every point
out vec4 frag;

void main() {
    vec4 q = texelFetch(probe_points, ivec2(gl_FragCoord.xy), 0);
    frag = vec4(detail_density(q.w, q.xyz, probe_footprint), 0.0, 0.0, 1.0);
}
