#version 430
// Test probe: (type_profile(h, t), type_density(m, h, t)) with (m, h, t) = texel.xyz of unit 0's input.
#include "clouds/volume/shape.glsl"

layout(binding = 0) uniform sampler2D probe_points;
out vec4 frag;

void main() {
    vec4 q = texelFetch(probe_points, ivec2(gl_FragCoord.xy), 0);
    frag = vec4(type_profile(q.y, q.z), type_density(q.x, q.y, q.z), 0.0, 1.0);
}
