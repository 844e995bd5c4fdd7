// The whole sky colour for a unit view direction: Preetham by day faded to `night` over twilight,
// the sun disc, stars (sky/extras.glsl), all dimmed below the horizon. float64 reference: plugins/sky/radiance.py;
// uniforms set by plugins/sky/shader.py:set_sky_uniforms, constants passed as defines.
#include "sky/preetham.glsl"
uniform float turbidity;
uniform float sky_scale;        // HDR units per kcd/m²

#include "sky/extras.glsl"

// Chappuis absorption of the sky's light by the ozone layer, relative to a zenith sun (reference:
// ozone_transmittance): the slant path through a thin shell, longer again once the sun has set.
vec3 sky_ozone(float sun_y) {
    float m = (1.0 + OZONE_BELOW * max(-sun_y, 0.0)) / sqrt(max(sun_y, 0.0) * max(sun_y, 0.0) + OZONE_SHELL);
    return exp(-OZONE_DEPTH * (m - 1.0 / sqrt(1.0 + OZONE_SHELL)));
}

vec3 sky_color(vec3 v) {
    vec3 s = sky_sun_dir;
    float day = smoothstep(DAY_LO, DAY_HI, s.y);
    vec3 ozone = pow(sky_ozone(s.y), vec3(max(v.y, 0.0) * max(v.y, 0.0)));
    vec3 rgb = mix(night_color, sky_scale * sky_preetham(v, s, turbidity) * ozone, day);
    return rgb * sky_below_horizon(v.y) + sky_extras(v, s);
}
