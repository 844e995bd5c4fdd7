// The air's aerial perspective over one pixel's ray (sky/aerial.comp for the sky's own pass,
// light_shafts/froxel_apply.comp where the shafts composite the air): (in-scattered light, grey
// transmittance) out to a distance, marched per pixel through the sky's atmosphere and LUTs
// (AERIAL_STEPS segments) or, with AERIAL_VOLUME 1, rebuilt from the froxel volume (sky/aerial_volume.comp:
// the air's colour and extinction, read trilinearly at (uv, the slice of d, sky/aerial_slices.glsl)); a ray
// longer than its range (far clouds), or whose froxels straddle the horizon, marches itself.
// The includer has lib/frame.glsl, lib/view_ray.glsl, sky/atmosphere.glsl and `uniform float view_r`.
// float64 reference: plugins/sky/atmosphere.py aerial_perspective.
#if AERIAL_VOLUME
#include "sky/aerial_slices.glsl"
layout(binding = 13) uniform sampler3D aerial_volume;
uniform float aerial_range;    // m: the volume's last slice (plugins/sky/aerial.py volume_range)
#endif

vec4 aerial(vec3 dir, float distance) {
    vec3 transmittance;
    vec3 light = atm_aerial(view_r, dir.y, sun_dir.y, dot(dir, sun_dir), distance, AERIAL_STEPS, transmittance);
    return vec4(light, dot(transmittance, vec3(1.0 / 3.0)));
}

#if AERIAL_VOLUME
// Whether the four froxel columns the pixel at uv reads from all end on the ground, or all leave the air
// through its top: across the horizon their air differs (a ray into the thin air above it, one down
// through the densest), and the pixels there march their own rays.
bool froxels_agree(vec2 uv) {
    vec2 n = vec2(textureSize(aerial_volume, 0).xy);
    vec2 c0 = (floor(uv * n - 0.5) + 0.5) / n, c1 = c0 + 1.0 / n;
    float r = atm_clamp_radius(view_r);
    bool g = atm_hits_ground(r, view_ray_dir(c0, view_basis).y);
    return g == atm_hits_ground(r, view_ray_dir(vec2(c1.x, c0.y), view_basis).y)
        && g == atm_hits_ground(r, view_ray_dir(vec2(c0.x, c1.y), view_basis).y)
        && g == atm_hits_ground(r, view_ray_dir(c1, view_basis).y);
}
#endif

// The aerial perspective of the ray through uv (unit direction dir) out to `distance`.
vec4 aerial_at(vec3 dir, float distance, vec2 uv) {
#if AERIAL_VOLUME
    if (distance <= aerial_range && froxels_agree(uv)) {  // the air's colour and extinction (aerial_volume.comp)
        float w = aerial_slice_w(distance, aerial_range), first = 0.5 / float(textureSize(aerial_volume, 0).z);
        vec4 air = textureLod(aerial_volume, vec3(uv, max(w, first)), 0.0);
        float T = exp(-air.a * max(distance, 0.0));
        return vec4(air.rgb * (1.0 - T), T);
    }
#endif
    return aerial(dir, distance);
}

// The pixel's aerial perspective: its scene depth z (sky pixels, depth 1, already hold the whole ray: none),
// `ray` its view_ray, clouds in front covering cloud.x of it at distance cloud.y (lib/cloud_distance.glsl)
// hazed by their own distance: a AP(d_cloud) + (1 - a) AP(d).
vec4 aerial_pixel(float z, vec3 ray, vec2 uv, vec2 cloud) {
    vec3 dir = normalize(ray);
    vec4 ap = z >= 1.0 ? vec4(0.0, 0.0, 0.0, 1.0) : aerial_at(dir, view_depth(z, near, far) * length(ray), uv);
    if (cloud.x > 0.0) ap = cloud.x * aerial_at(dir, cloud.y, uv) + (1.0 - cloud.x) * ap;
    return ap;
}
