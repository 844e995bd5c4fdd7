// The analytic sky along a pixel's view ray (sky/sky.glsl); alpha 0: open sky (color.a is the sky
// occlusion, atmos/render_core.py). Needs lib/frame.glsl (view_basis) first.
#include "lib/view_ray.glsl"
#include "sky/sky.glsl"

vec4 sky_pixel(vec2 uv) {
    return vec4(sky_color(view_ray_dir(uv, view_basis)), 0.0);
}
