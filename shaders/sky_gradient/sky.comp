#version 430
// Sky gradient, one compute invocation per pixel: where nothing was drawn (depth 1), the zenith/horizon
// blend, a glow round the sun and its disc along the pixel's view ray (float64 twin:
// plugins/sky_gradient/__init__.py gradient_sky), written into the colour with alpha 0 (open sky: color.a
// is the sky occlusion, atmos/render_core.py). view_basis, sun_dir, sun_color: the frame block.
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#include "lib/sun_disc.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D scene_depth;
layout(binding = 0, rgba16f) writeonly uniform image2D color_image;
uniform vec3 zenith;
uniform vec3 horizon;
uniform vec3 ground;
uniform vec4 sun_look;         // (disc chord, gain, glare, radians per pixel): SkyGradientSettings' sun disc

vec3 gradient_sky(vec3 dir) {
    vec3 s = normalize(sun_dir);
    float up = dir.y;
    vec3 sky = mix(horizon, zenith, pow(clamp(up, 0.0, 1.0), 0.6));
    sky = mix(sky, ground, smoothstep(0.0, -0.08, up));
    float day = smoothstep(-0.15, 0.1, s.y);
    sky *= mix(0.05, 1.0, day);
    vec3 disc = sun_disc(dir, s, sun_look.x, sun_look.y, sun_look.z, sun_look.w) * (1.0 - smoothstep(0.0, -0.01, up));
    return sky + sun_color * day * (0.25 * pow(max(dot(dir, s), 0.0), 32.0) + disc);
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(px, size)) || texelFetch(scene_depth, px, 0).r < 1.0) return;
    imageStore(color_image, px, vec4(gradient_sky(view_ray_dir((vec2(px) + 0.5) / vec2(size), view_basis)), 0.0));
}
