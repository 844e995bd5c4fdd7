#version 430
// Cloud ground shadows (thesis 7.3.1): the scene point behind each pixel is projected along the
// direction toward the sun onto the middle of the cloud layer, where the top-view summed density
// mix(A, B, t) (layer 0 of the density maps, each set at its own placement) gives the optical depth.
// One invocation per pixel multiplies the colour in place by 1 - weight (1 - exp(-tau)), its alpha
// (the sky occlusion) kept; plugins/clouds/shadows/reference.py is the same in numpy.
// The optical depth comes from the cloud shadow map (clouds/shadows/shadow_map.glsl, one fetch), or with
// CLOUD_SHADOW_EXACT (the shadows placed apart from the volume) from the column sums themselves.
// view_basis, camera_pos, near, far, sun_dir: the frame block (lib/frame.glsl)
layout(local_size_x = 8, local_size_y = 8) in;
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#if CLOUD_SHADOW_EXACT
#include "clouds/volume/column.glsl"
#define SUN_TAU sun_optical_depth
#else
#include "clouds/shadows/shadow_map.glsl"
#define SUN_TAU cloud_shadow_tau
#endif
layout(binding = 0, rgba16f) uniform image2D color_image;
layout(binding = 2) uniform sampler2D scene_depth;
uniform float weight;          // direct_fraction × horizon fade (reference.direct_weight)

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(pixel, size))) return;
    float depth = texelFetch(scene_depth, pixel, 0).r;
    if (depth >= 1.0 || weight <= 0.0) return;         // no geometry: the pixel stays as it is
    vec2 uv = (vec2(pixel) + 0.5) / vec2(textureSize(scene_depth, 0));
    vec3 p = camera_pos + view_ray(uv, view_basis) * view_depth(depth, near, far);
    float tau = SUN_TAU(p, sun_dir);
    vec4 c = imageLoad(color_image, pixel);
    imageStore(color_image, pixel, vec4(c.rgb * (1.0 - weight * (1.0 - exp(-tau))), c.a));
}
