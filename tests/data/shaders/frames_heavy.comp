#version 430
// Synthetic heavy simulation slice for benchmarks/bench_frame_pacing.py: ITERATIONS rounds of
// math per texel over z-layers [z0, z0 + layers) of a 3D image, reading the previous result.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(rgba16f, binding = 0) uniform writeonly image3D dst;
layout(rgba16f, binding = 1) uniform readonly image3D src;
uniform int z0;
uniform int iterations;
uniform float time;
void main() {
    ivec3 p = ivec3(gl_GlobalInvocationID.xy, z0 + int(gl_GlobalInvocationID.z));
    ivec3 size = imageSize(dst);
    if (any(greaterThanEqual(p, size))) return;
    vec3 q = vec3(p) / vec3(size) + vec3(time * 0.05, 0.0, time * 0.02);
    vec4 acc = imageLoad(src, p) * 0.5;
    for (int i = 0; i < iterations; ++i) {
        q = fract(q * 1.618 + vec3(0.31, 0.17, 0.53)) - 0.5;
        acc.xyz += sin(q * 6.2831 + acc.zxy) * 0.01;
        acc.w += dot(q, q) * 0.001;
    }
    imageStore(dst, p, vec4(fract(acc.xyz), fract(acc.w)));
}
