// The FBM fog medium and its ray march (fbm-raymarched-fog.txt); mirrored in float64 by
// atmos/plugins/volumetric_fog/reference.py. Needs lib/hash.glsl and lib/value_noise.glsl first; the sun's
// direction is the frame block's (lib/frame.glsl); the noise is volumetric_fog/lattice.glsl's; with
// FOG_CLOUD_SHADOWS the sunlight is the clouds' shadow map's too (clouds/shadows/shadow_map.glsl).
//   density(p) = bias - falloff * |(p - center) / scale| + fbm(frequency * (p - center - wind * fog_time))
// Positive density only inside the ellipsoid |(p - center) / scale| < (bias + 1 - 2^-octaves) / falloff,
// so the march covers the part of the ray inside it (and before the scene surface / max_distance).
#include "lib/frame.glsl"
#include "volumetric_fog/lattice.glsl"
#ifdef FOG_CLOUD_SHADOWS
#include "clouds/shadows/shadow_map.glsl"
#endif

uniform vec3 center;
uniform vec3 scale;
uniform float bias;
uniform float falloff;
uniform float frequency;
uniform vec3 wind;
uniform float fog_time;       // s the noise has drifted (0 unless animated)
uniform int octaves;
uniform float absorption;      // extinction per metre at density 1
uniform int steps;             // view-ray samples
uniform int light_steps;       // samples toward the sun per view sample
uniform float light_step;      // metres between light samples
uniform float max_distance;
uniform vec3 sun_light;        // scattering colour * sun radiance
uniform vec3 ambient_light;    // ambient colour

float fog_density(vec3 p) {
    vec3 q = p - center;
    return bias - falloff * length(q / scale) + lattice_fbm(frequency * (q - wind * fog_time), octaves);
}

// [enter, leave] of the ray inside the medium's bounding ellipsoid, clipped to [0, limit]; enter >= leave: miss.
vec2 fog_range(vec3 ro, vec3 dir, float limit) {
    limit = min(limit, max_distance);
    if (falloff <= 0.0) return vec2(0.0, limit);
    float radius = (bias + 1.0 - exp2(-float(clamp(octaves, 0, 16)))) / falloff;
    if (radius <= 0.0) return vec2(0.0, -1.0);
    vec3 o = (ro - center) / scale, d = dir / scale;
    float a = dot(d, d), b = dot(o, d), c = dot(o, o) - radius * radius;
    float disc = b * b - a * c;
    if (disc <= 0.0) return vec2(0.0, -1.0);
    float r = sqrt(disc);
    return vec2(max((-b - r) / a, 0.0), min((-b + r) / a, limit));
}

// The sun's transmittance from p: light_steps samples light_step apart toward the sun (stops at 0.01);
// with FOG_CLOUD_SHADOWS times the clouds' exp(-tau) there (the cloud shadow map, one fetch).
float fog_sun_transmittance(vec3 p) {
    float tl = 1.0;
    for (int j = 0; j < light_steps; ++j) {
        float dl = fog_density(p + sun_dir * (float(j) * light_step));
        if (dl > 0.0) {
            tl *= exp(-absorption * dl * light_step);
            if (tl <= 0.01) break;
        }
    }
#ifdef FOG_CLOUD_SHADOWS
    tl *= exp(-cloud_shadow_tau(p, sun_dir));
#endif
    return tl;
}

// Premultiplied result: rgb = in-scattered light, a = transmittance along the ray up to `limit`.
vec4 fog_march(vec3 ro, vec3 dir, float limit) {
    vec2 range = fog_range(ro, dir, limit);
    vec3 light = vec3(0.0);
    float trans = 1.0;
    if (range.y <= range.x || steps < 1) return vec4(light, trans);
    float dt = (range.y - range.x) / float(steps);
    for (int i = 0; i < steps; ++i) {
        vec3 p = ro + dir * (range.x + (float(i) + 0.5) * dt);
        float d = fog_density(p);
        if (d <= 0.0) continue;
        float step_t = exp(-absorption * d * dt);
        light += trans * (1.0 - step_t) * (ambient_light + sun_light * fog_sun_transmittance(p));
        trans *= step_t;
        if (trans <= 0.01) break;
    }
    return vec4(light, trans);
}
