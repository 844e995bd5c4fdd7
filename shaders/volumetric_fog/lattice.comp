#version 430
// The volumetric fog's lattice (volumetric_fog/lattice.glsl): texel c holds vn_lattice3(c, vn_key(seed)),
// exact in r32f (24-bit values).
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(r32f, binding = 0) writeonly uniform image3D lattice;
uniform uint seed;

void main() {
    ivec3 c = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(c, imageSize(lattice)))) return;
    imageStore(lattice, c, vec4(vn_lattice3(c, vn_key(seed)), 0.0, 0.0, 1.0));
}
