#version 430
// One channel of a 3D probability texture -> per-cell float32 [x + nx * (y + ny * z)] (see
// CloudAutomaton.step_with_texture). One invocation per cell.
layout(local_size_x = 64) in;

#include "clouds/automaton/common.glsl"

layout(binding = 0) uniform sampler3D u_probabilities;
uniform int u_channel;
layout(std430, binding = 6) writeonly buffer Prob { float prob[]; };

void main() {
    uint c = invocation_index();
    uint cells = uint(u_size.x * u_size.y * u_size.z);
    if (c >= cells) {
        return;
    }
    ivec3 p = ivec3(int(c % uint(u_size.x)), int((c / uint(u_size.x)) % uint(u_size.y)),
                    int(c / uint(u_size.x * u_size.y)));
    prob[c] = clamp(texelFetch(u_probabilities, p, 0)[u_channel], 0.0, 1.0);
}
