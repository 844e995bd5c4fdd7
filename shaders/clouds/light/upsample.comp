#version 430
// Transmittance of a coarse shading grid sampled trilinearly at the fine voxel centres (reference.upsample):
// what hardware linear filtering of the coarse texture gives a renderer at the same texture coordinates.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
#include "clouds/light/sample.glsl"
layout(binding = 0) uniform sampler3D coarse;
uniform ivec3 coarse_size;
layout(r32f, binding = 0) uniform writeonly image3D fine;

void main() {
    ivec3 n = imageSize(fine);
    ivec3 i = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(i, n))) return;
    vec3 p = (vec3(i) + 0.5) * vec3(coarse_size) / vec3(n) - 0.5;
    imageStore(fine, i, vec4(clamp(shading_trilinear(coarse, coarse_size, p), 0.0, 1.0)));
}
