#version 430
// Coarse density for a shading scale: the mean of SCALE^3 trilinear samples of the fine volume per coarse
// cell (reference.downsample). Summing value / SCALE^3 keeps huge densities finite.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
#include "clouds/light/sample.glsl"
layout(binding = 0) uniform sampler3D fine;
uniform ivec3 fine_size;
layout(r32f, binding = 0) uniform writeonly image3D coarse;

void main() {
    ivec3 n = imageSize(coarse);
    ivec3 k = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(k, n))) return;
    vec3 h = vec3(fine_size) / vec3(n);
    const float w = 1.0 / float(SCALE * SCALE * SCALE);
    float sum = 0.0;
    for (int i = 0; i < SCALE; ++i)
        for (int j = 0; j < SCALE; ++j)
            for (int l = 0; l < SCALE; ++l) {
                vec3 sub = (vec3(k) + (vec3(i, j, l) + 0.5) / float(SCALE)) * h - 0.5;
                sum += w * shading_trilinear(fine, fine_size, sub);
            }
    imageStore(coarse, k, vec4(sum));
}
