#version 430
// The ray-marched cloud layer (plugins/clouds/raymarch), one compute invocation per low-res texel
// (i, j): the ray through the full-res pixel (i, j) * factor + sample_offset (clouds/raymarch/march.glsl).
// MARCH_ONTO 0 (factor r > 1): stores premultiplied (light, a) into "cloud_raymarch_color", (a * distance,
// a) into "cloud_raymarch_distance" and the scene's window depth the ray saw into "cloud_raymarch_depth"
// (r32f), every texel written. MARCH_ONTO 1 (factor 1): composites onto "color" in place as blend_over
// would (layer + (1 - a) colour, alpha too) and, MARCH_DISTANCE 1, its distance onto "cloud_distance"
// with its own alpha (atmos/composition.py); MARCH_DISTANCE 2 (its first writer, no clear before) stores it.
#include "clouds/raymarch/march.glsl"
#include "lib/over.glsl"
#ifndef MARCH_ONTO
#define MARCH_ONTO 0
#endif
#ifndef MARCH_DISTANCE
#define MARCH_DISTANCE 0
#endif
layout(local_size_x = 8, local_size_y = 8) in;
#if MARCH_ONTO
layout(binding = 0, rgba16f) uniform image2D color_image;
#if MARCH_DISTANCE == 1
layout(binding = 1, rg32f) uniform image2D distance_image;
#elif MARCH_DISTANCE == 2
layout(binding = 1, rg32f) writeonly uniform image2D distance_image;
#endif
#else
layout(binding = 0, rgba16f) writeonly uniform image2D color_image;
layout(binding = 1, rg32f) writeonly uniform image2D distance_image;
layout(binding = 2, r32f) writeonly uniform image2D depth_image;
#endif
uniform int factor;            // resolution divisor r

void main() {
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(texel, imageSize(color_image)))) return;
    vec4 color;
    vec2 distance;
    float depth;
    cloud_march(min(texel * factor + sample_offset, frame_size - 1), color, distance, depth);
#if MARCH_ONTO
    imageStore(color_image, texel, over(color, imageLoad(color_image, texel)));
#if MARCH_DISTANCE == 1
    imageStore(distance_image, texel, vec4(over(distance, imageLoad(distance_image, texel).rg), 0.0, 0.0));
#elif MARCH_DISTANCE == 2
    imageStore(distance_image, texel, vec4(distance, 0.0, 0.0));
#endif
#else
    imageStore(color_image, texel, color);
    imageStore(distance_image, texel, vec4(distance, 0.0, 0.0));
    imageStore(depth_image, texel, vec4(depth, 0.0, 0.0, 0.0));
#endif
}
