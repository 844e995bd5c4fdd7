// The cloud volume as the renderers see it: density and transmittance toward the sun, each
// mix(A, B, t) of the two latest completed steps, and the light model of plugins/clouds/light/medium.py:
// source per unit extinction J = sun_source(y) * sum_i b^i p(cos; c^i g) P_i(T)
//                              + 2 (sky_source w_sky + ground_source w_ground),
// ground_source = ground_sky_source + G ground_sun_source (G: the clouds' shadow on the ground),
// P_i: the octaves' transmittances (lib/octaves.glsl: light forward-scattered i times on its way, the
// last all higher counts), w: each face's share of the diffusion solution between a slab's lit faces
// (ambient_source; medium.py ambient_weights); plus the diffusion field's term (diffusion_part) where the
// set has one: the light turned aside (diffuse), where the octaves carry what stays forward.
layout(binding = 0) uniform sampler3D density_a;
layout(binding = 1) uniform sampler3D density_b;
layout(binding = 2) uniform sampler3D trans_a;       // at the shading scale; same texture coordinates
layout(binding = 3) uniform sampler3D trans_b;
layout(binding = 10) uniform sampler3D columns_a;     // the light volume's columns (up, down), shading scale
layout(binding = 11) uniform sampler3D columns_b;
layout(binding = 16) uniform sampler3D diffusion_a;   // the diffusion field (phi, F), its own grid
layout(binding = 17) uniform sampler3D diffusion_b;
uniform float ms_diffusion;    // its weight beta (CloudLightSettings.ms_diffusion); 0: no field bound
uniform float t;
uniform ivec3 a_shift;         // cells from B's cell to A's at the same world point (CloudSets.a_shift)
uniform int has_shading;       // 0: no transmittance textures, T = 1
const int SUN_HEIGHTS = 5;     // light.py SUN_HEIGHTS
layout(std140, binding = 2) uniform CloudLight {   // the light that moves with the sun (light.py write_light)
    vec3 sun_sources[SUN_HEIGHTS];  // albedo * sun irradiance at the volume's heights k / 4 (uvw.y, base to
                                    // top): the sun's colour there (already 0 with the sun below the horizon)
    vec3 sky_source;                // albedo * sky radiance / 2
    vec3 ground_sky_source;         // albedo * the ground's sky-lit radiance / 2
    vec3 ground_sun_source;         // albedo * the ground's sunlit radiance / 2, were no cloud in the way
    vec3 light_dir;                 // toward the sun, unit (the frame block's sun_dir for the scene's sun)
    float sun_span;                 // sun_sources' heights span this many layer heights (1; more for a
                                    // cloud type's towers above the layer: volume/shape.py march_top)
};
layout(std140, binding = 3) uniform CloudGround {  // written on the GPU (plugins/clouds/light/ground.py)
    vec4 cloud_ground;              // x: G, the ground's mean sun transmittance through the clouds
};
uniform vec3 phase_lobes;      // g, g2, w
uniform float outward_share;   // the phase's share H of the hemisphere about a direction (medium.hemisphere_share)
uniform vec3 ms_octaves;       // a (attenuation), b (contribution), c (eccentricity)
uniform float column_tau;      // sigma_t * cell height: optical depth of one cell of density 1, vertically
uniform float albedo;          // CloudSettings.albedo: how sky and ground light fade into the cloud (ambient_source)
uniform float edge_fade;       // CloudSettings.edge_fade: density fades to 0 toward the inscribed circle
#include "clouds/volume/edge.glsl"
const float PI = 3.14159265358979;
#include "lib/hdr_max.glsl"

// Trilinear at level 0 with clamp to edge and float32 weights (clouds/light/reference.py multilinear): a
// texture unit's filter takes 8-bit sub-texel weights on some GPUs (a machine with an NVIDIA GPU), up to
// 1/256 of the texels' difference off, percents of T where it falls by orders of magnitude between cells.
vec4 texel_trilinear(sampler3D s, vec3 uvw) {
    ivec3 n = textureSize(s, 0);
    vec3 p = clamp(uvw * vec3(n) - 0.5, vec3(0.0), vec3(n - 1));
    ivec3 i = ivec3(p), j = min(i + 1, n - 1);      // p >= 0: ivec3 is its floor
    vec3 f = p - vec3(i), g = 1.0 - f;               // (1 - f) a + f b: no cancellation when b << a
    vec4 y0 = g.y * (g.x * texelFetch(s, i, 0) + f.x * texelFetch(s, ivec3(j.x, i.y, i.z), 0))
            + f.y * (g.x * texelFetch(s, ivec3(i.x, j.y, i.z), 0) + f.x * texelFetch(s, ivec3(j.x, j.y, i.z), 0));
    vec4 y1 = g.y * (g.x * texelFetch(s, ivec3(i.x, i.y, j.z), 0) + f.x * texelFetch(s, ivec3(j.x, i.y, j.z), 0))
            + f.y * (g.x * texelFetch(s, ivec3(i.x, j.y, j.z), 0) + f.x * texelFetch(s, j, 0));
    return g.z * y0 + f.z * y1;
}

// The volume's lookups: the texture unit's filter, or texel_trilinear (8 fetches) where
// CLOUD_EXACT_FILTER is defined before the include (sprite.vert: once per sprite).
#ifdef CLOUD_EXACT_FILTER
#define CLOUD_SAMPLE(s, uvw) texel_trilinear(s, uvw)
#else
#define CLOUD_SAMPLE(s, uvw) textureLod(s, uvw, 0.0)
#endif

// uvw: B's texture coordinates (the volume is drawn at B's placement); A's are offset by a_shift.
vec3 a_uvw(vec3 uvw) {
    vec3 size = vec3(textureSize(density_a, 0));
    return (uvw * size + vec3(a_shift)) / size;      // a cell centre stays one exactly
}

float cloud_density(vec3 uvw) {
    return cloud_edge_weight(uvw.xz, edge_fade) * mix(CLOUD_SAMPLE(density_a, a_uvw(uvw)).r, CLOUD_SAMPLE(density_b, uvw).r, t);
}

float cloud_transmittance(vec3 uvw) {
    return has_shading == 0 ? 1.0 : mix(CLOUD_SAMPLE(trans_a, a_uvw(uvw)).r, CLOUD_SAMPLE(trans_b, uvw).r, t);
}

// (tau_up, tau_down): optical depth from uvw straight up and straight down to the volume's faces, from
// the light volume's columns (plugins/clouds/light/columns.py: density integrals in fine cells, per set, at the
// shading scale) times column_tau and the edge fade (which depends on x and z only).
vec2 cloud_columns(vec3 uvw) {
    vec2 c = mix(CLOUD_SAMPLE(columns_a, a_uvw(uvw)).rg, CLOUD_SAMPLE(columns_b, uvw).rg, t);
    return column_tau * cloud_edge_weight(uvw.xz, edge_fade) * c;
}

// albedo * the sun's irradiance at height fraction v of the volume (uvw.y: 0 base, 1 top; towers up to
// sun_span), linear between the SUN_HEIGHTS samples (light.py sun_source_at): clouds' tops see a less
// reddened sun than their bases, and keep it after the bases' sunset.
vec3 sun_source_at(float v) {
    float x = clamp(v / max(sun_span, 1.0), 0.0, 1.0) * float(SUN_HEIGHTS - 1);
    int k = min(int(x), SUN_HEIGHTS - 2);
    return mix(sun_sources[k], sun_sources[k + 1], x - float(k));
}

// The phase function's mean cosine g_mean = (1 - w) g + w g2.
float mean_cosine() {
    return (1.0 - phase_lobes.z) * phase_lobes.x + phase_lobes.z * phase_lobes.y;
}

#include "lib/octaves.glsl"

// How fast each octave's transmittance falls with the sun's optical depth, as T^e: (1, 1, 1, a) (exact
// for the first and last deep in the cloud); the sprites' spread across a sprite and the 2D far field's
// thickness and relief scale them so.
vec4 octave_exponents() {
    return vec4(1.0, 1.0, 1.0, ms_octaves.x);
}

// Octave weights b^i P_i from the octaves' transmittances P (the 2D far field passes the volume's means
// by rank).
vec4 octave_weights_of(vec4 P) {
    float b = ms_octaves.y;
    return P * vec4(1.0, b, b * b, b * b * b);
}

// Octave weights b^i P_i(T) at sun transmittance T.
vec4 octave_weights(float T) {
    return octave_weights_of(octave_transmittances(T, ms_octaves.x));
}

// sinh(x) / sinh(y) for 0 <= x <= y, y > 0, without overflow.
float sinh_ratio(float x, float y) {
    return exp(x - y) * (1.0 - exp(-2.0 * x)) / (1.0 - exp(-2.0 * y));
}

// Sky and ground light toward the eye along ray_y (the view ray's y) (medium.py ambient_weights): each
// face's share of the diffusion solution between the columns above and below, sinh(kappa (tau_other + z)) /
// sinh(kappa D) with D = tau_up + tau_down + 2z, kappa = sqrt(3 (1 - albedo) (1 - albedo g_mean)) (linear
// at albedo 1: a furnace of equal sky and ground stays exact); where the column is thin, the phase's
// forward share g_mean ray_y moves light from the ground's share to the sky's.
vec3 ambient_source(float tau_up, float tau_down, float ray_y) {
    float g = mean_cosine();
    float z = 2.0 / (3.0 * (1.0 - min(albedo * g, 0.99)));
    float D = tau_up + tau_down + 2.0 * z;
    float kappa = sqrt(max(3.0 * (1.0 - albedo) * (1.0 - albedo * g), 0.0));
    vec2 w = kappa * D < 1e-3 ? vec2(tau_down + z, tau_up + z) / D
           : vec2(sinh_ratio(kappa * (tau_down + z), kappa * D), sinh_ratio(kappa * (tau_up + z), kappa * D));
    float s = w.x + w.y;
    float f = 0.5 * s * g * ray_y * exp(-(tau_up + tau_down) / (2.0 * z));
    w = clamp(w + vec2(f, -f), 0.0, s);
    vec3 ground_source = ground_sky_source + cloud_ground.x * ground_sun_source;
    return 2.0 * (sky_source * w.x + ground_source * w.y);
}

#include "lib/phase.glsl"

// The diffusion field (plugins/clouds/light/diffusion.py): (phi, F) of the sun's scattered fluence for unit
// irradiance, mix(A, B, t) like the density.
vec4 cloud_diffusion(vec3 uvw) {
    return mix(CLOUD_SAMPLE(diffusion_a, a_uvw(uvw)), CLOUD_SAMPLE(diffusion_b, uvw), t);
}

// The field's share of J beside the octaves for a field value f = (phi, F) under the sun's `source`: source beta
// max(phi - 3 g_mean F.ray, -c 2 H phi, 0) / 4pi (c = dot(ray, light_dir); diffusion.field_radiance).
// Against the sun the truncated P1 falls to 0 at a lit surface, where F runs with the sun's light; the
// light a lit surface sends back fills only the outward hemisphere there (phi / 2pi, twice the
// isotropic part), and scattering toward the outside takes the phase's share H of that hemisphere
// (outward_share: 0.90 at the defaults), so J is never below -c 2 H phi / 4pi.
vec3 diffusion_light(vec4 f, vec3 ray_dir, vec3 source) {
    if (ms_diffusion <= 0.0) return vec3(0.0);
    float c = dot(ray_dir, light_dir), back = -c * 2.0 * outward_share;
    float L = max(max(f.x - 3.0 * mean_cosine() * dot(f.yzw, ray_dir), back * f.x), 0.0) / (4.0 * PI);
    return source * (ms_diffusion * L);
}

vec3 diffusion_part(vec3 uvw, vec3 ray_dir) {
    return ms_diffusion <= 0.0 ? vec3(0.0) : diffusion_light(cloud_diffusion(uvw), ray_dir, sun_source_at(uvw.y));
}

// source * sum_i w_i p(cos; c^i g): the sun's part of J for a view ray with dot(ray, light_dir) = c
// under the sun's `source` (sun_source_at the point's height).
vec3 sun_part(vec4 w, float c, vec3 source) {
    float e = 1.0, sum = 0.0;
    for (int i = 0; i < 4; ++i) {
        sum += w[i] * mix(hg(c, phase_lobes.x * e), hg(c, phase_lobes.y * e), phase_lobes.z);
        e *= ms_octaves.z;
    }
    return source * sum;
}

// J at uvw for a view ray along ray_dir (world, unit), with sun transmittance T (ny: unused, kept
// for the callers).
vec3 cloud_source_with(vec3 uvw, vec3 ray_dir, float ny, float T) {
    vec2 c = cloud_columns(uvw);
    return sun_part(octave_weights(T), dot(ray_dir, light_dir), sun_source_at(uvw.y)) + diffusion_part(uvw, ray_dir)
         + ambient_source(c.x, c.y, ray_dir.y);
}

// J at uvw for a view ray along ray_dir (world, unit): the shading volume's sun transmittance.
vec3 cloud_source(vec3 uvw, vec3 ray_dir, float ny) {
    return cloud_source_with(uvw, ray_dir, ny, cloud_transmittance(uvw));
}
