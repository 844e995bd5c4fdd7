// The physical sky along a pixel's view ray (SkySettings.model = "physical"): the sky-view LUT,
// `night` (the airglow and starlight the model leaves out) faded in over twilight, the sun disc and
// stars of sky/extras.glsl; alpha 0: open sky. float64 reference: plugins/sky/radiance.py:physical_sky_color.
// Needs lib/frame.glsl (view_basis) first.
layout(binding = 12) uniform sampler2D sky_view;
uniform float view_r;          // the camera's radius from the planet's centre
#include "lib/view_ray.glsl"
#include "sky/atmosphere.glsl"
#include "sky/extras.glsl"

vec4 sky_pixel(vec2 uv) {
    vec3 v = view_ray_dir(uv, view_basis);
    vec3 s = sky_sun_dir;
    float vh = length(v.xz), sh = length(s.xz);
    float cos_az = (vh > 1e-6 && sh > 1e-6) ? clamp(dot(v.xz, s.xz) / (vh * sh), -1.0, 1.0) : 1.0;
    vec3 rgb = textureLod(sky_view, atm_sky_view_uv(view_r, v.y, cos_az), 0.0).rgb;
    rgb += night_color * (1.0 - smoothstep(DAY_LO, DAY_HI, s.y));
    return vec4(rgb + sky_extras(v, s), 0.0);
}
