// The whole sky colour for a unit view direction: Preetham by day faded to `night` over twilight,
// the sun disc, stars, all dimmed below the horizon. float64 reference: plugins/sky/reference.py;
// uniforms set by plugins/sky/shader.py:set_sky_uniforms, constants passed as defines.
#include "sky/preetham.glsl"
#include "sky/stars.glsl"

uniform vec3 sky_sun_dir;       // unit, toward the sun
uniform vec3 sky_sun_color;
uniform float turbidity;
uniform float sky_scale;        // HDR units per kcd/m²
uniform vec2 sun_chords;        // |v − s| where the disc's soft edge starts and ends
uniform float sun_gain;
uniform vec3 night_color;
uniform uint star_threshold;    // 0: no stars
uniform float star_brightness;
uniform float twinkle;
uniform float sky_time;         // seconds, wrapped to the twinkle period
uniform float pixel_angle;      // radians per pixel

vec3 sky_color(vec3 v) {
    vec3 s = sky_sun_dir;
    float day = smoothstep(DAY_LO, DAY_HI, s.y);
    vec3 rgb = mix(night_color, sky_scale * sky_preetham(v, s, turbidity), day);
    float inside = 1.0 - smoothstep(sun_chords.x, sun_chords.y, length(v - s));
    vec3 extra = sun_gain * inside * sky_sun_color;
    if (star_threshold > 0u)
        extra += sky_stars(v, s.y, sky_time, pixel_angle, star_threshold, star_brightness, twinkle);
    return (rgb + extra) * mix(1.0, GROUND_DIM, smoothstep(0.0, -BELOW_FADE, v.y));
}
