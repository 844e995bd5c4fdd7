#version 430
// One octave's tileable noise volume: texel j holds the periodic noise at lattice coordinate
// (j + 0.5) / texels_per_cell, so the (period * texels_per_cell)^3 texture repeats seamlessly.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
#include "lib/gradient_noise.glsl"

layout(r32f, binding = 0) writeonly uniform image3D volume;
uniform int period;
uniform int texels_per_cell;
uniform uvec2 key;

void main() {
    ivec3 j = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(j, ivec3(period * texels_per_cell)))) return;
    vec3 q = (vec3(j) + 0.5) / float(texels_per_cell);
    imageStore(volume, j, vec4(periodic_gradient_noise(q, period, key), 0.0, 0.0, 1.0));
}
