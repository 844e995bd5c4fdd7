// What both skies (Preetham, sky.glsl; physical, physical.frag) draw over their radiance: the sun disc
// (limb-darkened, antialiased over a pixel) and its glare, the stars. float64 reference:
// plugins/sky/radiance.py (atmos/sun_disc.py sun_disc, star_field); uniforms set by plugins/sky/shader.py:set_sky_uniforms.
#include "sky/stars.glsl"

uniform vec3 sky_sun_dir;       // unit, toward the sun
uniform vec3 sky_sun_color;
uniform float sun_chord;        // |v − s| of the disc's angular radius
uniform float sun_gain;
uniform float sun_glare;
uniform vec3 night_color;
uniform uint star_threshold;    // 0: no stars
uniform float star_brightness;
uniform float twinkle;
uniform float sky_time;         // seconds, wrapped to the twinkle period
uniform float pixel_angle;      // radians per pixel

// 1 above the horizon, down to GROUND_DIM under it; reference: below_horizon.
float sky_below_horizon(float view_y) { return mix(1.0, GROUND_DIM, smoothstep(0.0, -BELOW_FADE, view_y)); }

#include "lib/sun_disc.glsl"

// The sun disc and its glare; reference: atmos/sun_disc.py sun_disc.
vec3 sky_sun_disc(vec3 v, vec3 s) {
    return sun_disc(v, s, sun_chord, sun_gain, sun_glare, pixel_angle) * sky_sun_color;
}

// Sun disc, glare and stars for view v, dimmed below the horizon like the Preetham sky.
vec3 sky_extras(vec3 v, vec3 s) {
    vec3 extra = sky_sun_disc(v, s);
    if (star_threshold > 0u)
        extra += sky_stars(v, s.y, sky_time, pixel_angle, star_threshold, star_brightness, twinkle);
    return extra * sky_below_horizon(v.y);
}
