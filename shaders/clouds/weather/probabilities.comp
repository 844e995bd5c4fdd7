#version 430
// (p_hum, p_act, p_ext, 0) per cell from the region volume; see clouds/weather/probabilities.glsl.
#include "clouds/weather/probabilities.glsl"
layout(local_size_x = 8, local_size_y = 8, local_size_z = 4) in;
layout(binding = 0) uniform sampler3D region;
layout(binding = 0, FORMAT) uniform writeonly image3D probs;
uniform ivec3 size;
uniform vec4 scales;

void main() {
    ivec3 q = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(q, size))) return;
    float r = texelFetch(region, q, 0).r;
    imageStore(probs, q, vec4(weather_probabilities(r, scales), 0.0));
}
