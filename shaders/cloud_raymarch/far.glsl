// The ray march's volumetric far field (float64 reference: plugins/cloud_raymarch/far_reference.py).
// Beyond the simulated volume (and across its edge fade, weighted by 1 - the edge weight) the layer's
// density at world p is the far field's cover c = far_field_density(p.xz, lod).x (cloud_far_field/
// field.glsl: the same octaves, drift and threshold as the 2D far field and the ground shadows) times a
// vertical profile over the layer's height fraction h (0 base, 1 top):
//   top = FAR_BASE + (1 - FAR_BASE) c          (thicker cover, taller clouds; the top is the iso-surface
//                                               h = top(c(x, z)): rounded domes over the cover's blobs)
//   profile = clamp((h - FAR_BASE) / FAR_BASE_SOFT, 0, 1) * clamp((top - h) / FAR_TOP_SOFT, 0, 1)
//   density = far_body * profile               (far_body: detail.glsl's K, a cloud body's density)
// which the march then erodes with the detail noise like the volume's density. Light (volume.glsl's
// model): the sun transmittance from a three-step march toward the sun through the same profile, the
// cover at each step read from the light-march channels d.yzw (baked light_step tiles apart toward the
// sun: no extra fetch); the sky light from the profile's analytic columns above and below.
// Requires volume.glsl (sun_part, octave_weights, ambient_source, sun_dir) included first.
#include "cloud_far_field/field.glsl"

const float FAR_BASE = 0.1;       // the flat base's height fraction
const float FAR_BASE_SOFT = 0.05; // ramp of the base
const float FAR_TOP_SOFT = 0.3;   // ramp below the top: the shell the detail noise carves
uniform float far_lod_scale;      // octave texels per metre x a full-res pixel's angle (rad)
uniform vec2 far_band;            // (base y, height) of the layer (m)
uniform float far_body;           // density of a far cloud's body
uniform vec3 far_sun;             // (step toward the sun (m), channels per step, layer fraction per step)

vec4 far_cover(vec2 xz, float s) {
    return far_field_density(xz, log2(max(far_lod_scale * s, 1e-6)));
}

float far_height(float y) {
    return (y - far_band.x) / far_band.y;
}

float far_profile(float h, float c) {
    if (c <= 0.0) return 0.0;
    float top = FAR_BASE + (1.0 - FAR_BASE) * c;
    return clamp((h - FAR_BASE) / FAR_BASE_SOFT, 0.0, 1.0) * clamp((top - h) / FAR_TOP_SOFT, 0.0, 1.0);
}

// The profile's integral from h to the top (layer fractions), ignoring the base ramp.
float far_above(float h, float top) {
    float x = max(top - h, 0.0);
    return x >= FAR_TOP_SOFT ? x - 0.5 * FAR_TOP_SOFT : x * x / (2.0 * FAR_TOP_SOFT);
}

// Cover at a fractional channel position x in [0, 3) of the light-march channels c.
float far_channel(vec4 c, float x) {
    int i = min(int(x), 2);
    return mix(c[i], c[i + 1], x - float(i));
}

// J (per unit extinction) of far-field density with cover channels c at height fraction h, seen along
// dir; sigma_t: extinction (1/m) at density 1.
vec3 far_source(vec4 c, float h, vec3 dir, float sigma_t) {
    float depth = 0.0;
    for (int k = 0; k < 3; ++k) {
        float x = (float(k) + 0.5) * far_sun.y;
        depth += far_profile(h + (float(k) + 0.5) * far_sun.z, far_channel(c, x));
    }
    float T = exp(-sigma_t * far_body * far_sun.x * depth);
    float top = FAR_BASE + (1.0 - FAR_BASE) * c.x, hb = max(h, FAR_BASE);
    float k = sigma_t * far_body * far_band.y;
    float up = k * far_above(hb, top), down = k * (far_above(FAR_BASE, top) - far_above(hb, top));
    return sun_part(octave_weights(T, up + down), dot(dir, sun_dir)) + ambient_source(up, down, dir.y);
}
