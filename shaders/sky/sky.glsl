// The whole sky colour for a unit view direction: Preetham by day faded to `night` over twilight,
// the sun disc, stars, all dimmed below the horizon. float64 reference: plugins/sky/reference.py;
// uniforms set by plugins/sky/shader.py:set_sky_uniforms, constants passed as defines.
#include "sky/preetham.glsl"
#include "sky/stars.glsl"

uniform vec3 sky_sun_dir;       // unit, toward the sun
uniform vec3 sky_sun_color;
uniform float turbidity;
uniform float sky_scale;        // HDR units per kcd/m²
uniform float sun_chord;        // |v − s| of the disc's angular radius
uniform float sun_gain;
uniform float sun_glare;
uniform vec3 night_color;
uniform uint star_threshold;    // 0: no stars
uniform float star_brightness;
uniform float twinkle;
uniform float sky_time;         // seconds, wrapped to the twinkle period
uniform float pixel_angle;      // radians per pixel

// Chappuis absorption of the sky's light by the ozone layer, relative to a zenith sun (reference:
// ozone_transmittance): the slant path through a thin shell, longer again once the sun has set.
vec3 sky_ozone(float sun_y) {
    float m = (1.0 + OZONE_BELOW * max(-sun_y, 0.0)) / sqrt(max(sun_y, 0.0) * max(sun_y, 0.0) + OZONE_SHELL);
    return exp(-OZONE_DEPTH * (m - 1.0 / sqrt(1.0 + OZONE_SHELL)));
}

// The sun disc (limb-darkened, antialiased over a pixel) and its glare; reference: sun_disc.
vec3 sky_sun_disc(vec3 v, vec3 s) {
    float c = length(v - s);
    float r = sun_chord;
    float half_edge = 0.5 * max(pixel_angle, EDGE_MIN * r);
    float cover = 1.0 - smoothstep(r - half_edge, r + half_edge, c);
    float mu = sqrt(max(1.0 - (c / r) * (c / r), LIMB_FLOOR * LIMB_FLOOR));
    float halo = sun_glare * (r / max(c, r)) * (r / max(c, r)) * (1.0 - smoothstep(0.0, GLARE_REACH, c));
    return sun_gain * (cover * pow(vec3(mu), SUN_LIMB) + halo) * sky_sun_color;
}

vec3 sky_color(vec3 v) {
    vec3 s = sky_sun_dir;
    float day = smoothstep(DAY_LO, DAY_HI, s.y);
    vec3 ozone = pow(sky_ozone(s.y), vec3(max(v.y, 0.0) * max(v.y, 0.0)));
    vec3 rgb = mix(night_color, sky_scale * sky_preetham(v, s, turbidity) * ozone, day);
    vec3 extra = sky_sun_disc(v, s);
    if (star_threshold > 0u)
        extra += sky_stars(v, s.y, sky_time, pixel_angle, star_threshold, star_brightness, twinkle);
    return (rgb + extra) * mix(1.0, GROUND_DIM, smoothstep(0.0, -BELOW_FADE, v.y));
}
