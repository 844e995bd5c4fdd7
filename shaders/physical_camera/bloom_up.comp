#version 430
// One bloom upsample (float64 twin: plugins/physical_camera/reference.py bloom_chain): the level becomes,
// in place, half itself and half the levels below it, which `coarse` holds (upsampled with
// lib/upsample2x.glsl): each coarser level weighs half the finer one.
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/upsample2x.glsl"
layout(binding = 0) uniform sampler2D coarse;
layout(binding = 0, rgba16f) uniform image2D level;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(level)))) return;
    vec3 own = imageLoad(level, p).rgb;
    imageStore(level, p, vec4(0.5 * (own + upsample2x(coarse, p)), 1.0));
}
