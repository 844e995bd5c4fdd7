// The fog's in-scattered colour in_color(dir) (fog.frag; the light shafts' march subtracts a share of it):
// fog_color, or with FOG_SKY_COLOR 1 fog_color × the sky's horizon light at the ray's angle from the sun
// (plugins/fog/sky_color.py sky_fog_color is the reference); with FOG_SUN 1 plus the sunlight it scatters,
// fog_sun_light × 4π p(θ) with the fog's two-lobe phase (plugins/fog/factors.py fog_light is the reference).
uniform vec3 fog_color;
#if FOG_SUN
#include "lib/phase.glsl"
uniform vec3 fog_sun_light;   // Sun.color × sun_scattering × daylight (0 once the sun has set)
uniform vec3 fog_sun_dir;     // unit, toward the sun
uniform vec3 fog_lobes;       // FogSettings.phase (g, g2, w)
vec3 sun_in(vec3 dir) { return fog_sun_light * (12.566370614359172 * phase2(dot(dir, fog_sun_dir), fog_lobes)); }
#else
vec3 sun_in(vec3 dir) { return vec3(0.0); }
#endif
#if FOG_SKY_COLOR
uniform vec3 fog_horizon[FOG_HORIZON_SAMPLES];   // the horizon's light at sin(angle from the sun / 2) = i / (n - 1) (sun_angle_table)
uniform vec3 fog_sky_sun;                        // unit, the sun the table was made for
vec3 in_color(vec3 dir) {
    float c = clamp(dot(dir, fog_sky_sun) / max(length(fog_sky_sun.xz), 1e-6), -1.0, 1.0);
    float u = sqrt(0.5 - 0.5 * c) * float(FOG_HORIZON_SAMPLES - 1);
    int i0 = min(int(floor(u)), FOG_HORIZON_SAMPLES - 2);
    return fog_color * mix(fog_horizon[i0], fog_horizon[i0 + 1], u - float(i0)) + sun_in(dir);
}
#else
vec3 in_color(vec3 dir) { return fog_color + sun_in(dir); }
#endif
