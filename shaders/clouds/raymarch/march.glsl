// The ray-marched cloud layer (plugins/clouds/raymarch), the body of clouds/raymarch/march.comp:
// cloud_march(pixel) marches the ray through the full-res pixel centre pixel + 0.5, from the near plane
// (or the layer's box) to the box's far side or the scene depth. Segments of length step_base +
// step_growth * s (s: distance from the camera), one density sample per segment at sample_jitter() of its
// length (0.5: the midpoint), extinction sigma_t * density, light J = volume.glsl's cloud_source.
// Sprite groups x height bands whose dilated max map is 0 are jumped over; a ray stops once its
// transmittance falls below min_transmittance or after `steps` samples. float64 reference:
// plugins/clouds/raymarch/reference.py. The density: shape.glsl's shaped_density (the cloud type's
// vertical shape of the simulated columns, or the simulation's own), eroded by detail.glsl.
// FAR_FIELD 1: the ray goes on through the layer's altitude band beyond the volume, to far_distance,
// through the volumetric far field (clouds/raymarch/far.glsl) weighted by 1 - the volume's edge weight
// (so the two cross-fade over the edge fade); from where the ray first reaches the fade ring the step
// grows by mix(step_growth, far_growth, that weight) of the distance and nothing is skipped.
// MARCH_VOLUME 0 (RaymarchCloudSettings.volume False, with FAR_FIELD 1): the far field alone, from where
// the ray reaches the fade ring on, the volume's density never sampled (another renderer draws it).
// Out: premultiplied (light, 1 - T); (a * distance, a) with distance the transmittance-weighted
// distance from the camera (m, atmos/composition.py); the scene's window depth the ray stopped at.
#include "clouds/volume/volume.glsl"
#include "clouds/raymarch/detail.glsl"
#include "clouds/volume/shape.glsl"
#ifndef FAR_FIELD
#define FAR_FIELD 0
#endif
#ifndef MARCH_VOLUME
#define MARCH_VOLUME 1
#endif
#if FAR_FIELD
#include "clouds/raymarch/far.glsl"
#endif
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
layout(binding = 4) uniform sampler3D skip_map;   // (groups x, bands, groups z): 0 = no density within
layout(binding = 9) uniform sampler2D scene_depth;
// view_basis, camera_pos, near, far: the frame block (lib/frame.glsl)
uniform vec3 layer_min;
uniform vec3 layer_max;
uniform vec3 cell_size;
uniform float sigma_t;         // extinction (1/m) at density 1
uniform int steps;             // most density samples per ray
uniform float step_base;       // m
uniform float step_growth;     // step grows by this share of the distance
uniform float min_transmittance;
uniform int skipping;          // 1: use skip_map
uniform vec3 skip_cells;       // cells per skip-map texel (group x, band height, group z)
uniform int max_skips;         // skip-map texels a ray can cross
uniform ivec2 frame_size;      // full-res pixels
uniform int jittered;          // 1: per-pixel first-sample offset (blue noise + jitter_shift); 0: midpoints
layout(std140, binding = 1) uniform March {   // what changes every frame (plugin.py MARCH_BLOCK), one write
    vec3 sun_march;        //  0  toward the sun, times the sun march's first step (m)
    float jitter_shift;    // 12  the frame's rotation of the offsets (0: fixed in time)
    ivec2 sample_offset;   // 16  the frame's jitter offset o in [0, r)^2 (march.comp)
};                         // 32 bytes
uniform float sun_growth;      // each sun-march step is this many times the last
uniform float far_distance;    // FAR_FIELD: the march ends this far from the camera (m)
uniform float far_growth;      // FAR_FIELD: the step's growth per metre of distance in the far field
uniform float pixel_angle;     // a full-res pixel's angle (rad): its width per metre of distance

// The marched density at uvw (volume.glsl's cloud_density, cloud_columns, column_tau): with a cloud type
// shape.glsl's type_density of the column's mean density (its up and down integrals over ny cells), of
// the type at the point (cloud_type_at).
// The box the march covers: the layer's, its top raised to march_top (towers of a cloud type).
vec3 march_max() {
    return vec3(layer_max.x, layer_min.y + march_top * (layer_max.y - layer_min.y), layer_max.z);
}

// Whether uvw (layer texture coordinates, y past 1 up to march_top) lies in the marched box.
bool in_march_box(vec3 uvw) {
    return all(greaterThanEqual(uvw, vec3(0.0))) && all(lessThanEqual(uvw, vec3(1.0, march_top, 1.0)));
}

float shaped_density(vec3 uvw, float ny) {
    if (cloud_type < 0.0) return cloud_density(uvw);
    vec2 c = cloud_columns(uvw);
    float t = cloud_type_at(layer_min.xz + uvw.xz * (layer_max.xz - layer_min.xz));
    return type_density((c.x + c.y) / (column_tau * ny), uvw.y, t);
}

// The blue noise (atmos/blue_noise.py) of the full-res pixel, tiled, rotated by jitter_shift (mod 1):
// the plugin turns it by the golden ratio every two r²-frame cycles of the resolve (each pixel marched
// twice with each offset: the resolve's drift test compares like with like), so each pixel's samples
// spread over the step and the temporal resolve averages them; 0 where nothing averages (resolution 1, no reprojection): there an offset that moved
// only flickered. Interleaved gradient noise, a set of diagonal lines, showed as a woven hatching
// under the history a moving camera reprojects.
layout(binding = 23) uniform sampler2D blue_noise;
float sample_jitter(vec2 pixel) {
    if (jittered == 0) return 0.5;
    return fract(texelFetch(blue_noise, ivec2(pixel) % textureSize(blue_noise, 0), 0).r + jitter_shift);
}

// Transmittance toward the sun from p (uvw: its texture coordinates): SUN_STEPS steps toward the
// sun, the first sun_march long, each next sun_growth times the last, one sample of the actual
// density (trilinear, eroded by the detail; 0 outside the box) at each step's midpoint, continued by
// the shading volume's T from where they end (1 outside the box). The shading volume holds T at its
// cell centres; trilinear between centres an e-fold apart it is 12 % too bright midway (0.68 for
// 0.61), at any depth, and it blurs the lit surface over a cell (a low sun crosses a dense cloud's
// cells lengthwise: dark bodies came out grey, rims weak); the march resolves the surface and the
// first cells behind it. SUN_STEPS 0: the shading volume's T at p. With a cloud type (shape.glsl) the
// shading volume holds the simulation's own shape (a stratus sheet under it would lie in the shadow of
// the simulated blob above), so the march goes on TYPE_SUN_STEPS more steps (4 + 2 reach 31.5 cells)
// and ends with 1; those long steps see the detail at their own length as the footprint (the noise
// finer than a step is not read).
float sun_transmittance(vec3 p, vec3 uvw, vec3 extent, float footprint) {
#if SUN_STEPS > 0
    float tau = 0.0, at = 0.0, h = length(sun_march);
    vec3 toward = sun_march / h;
    bool typed = cloud_type >= 0.0;
    int n = SUN_STEPS + (typed ? TYPE_SUN_STEPS : 0);
    for (int k = 0; k < n; ++k, at += h, h *= sun_growth) {
        vec3 q = p + toward * (at + 0.5 * h);
        vec3 s = (q - layer_min) / extent;
        if (!in_march_box(s)) return exp(-sigma_t * tau);
        tau += h * detail_density(shaped_density(s, extent.y / cell_size.y), q, k < SUN_STEPS ? footprint : max(footprint, h));
    }
    vec3 e = (p + toward * at - layer_min) / extent;
    bool inside = !typed && all(greaterThanEqual(e, vec3(0.0))) && all(lessThanEqual(e, vec3(1.0)));
    return exp(-sigma_t * tau) * (inside ? cloud_transmittance(e) : 1.0);
#else
    return cloud_transmittance(uvw);
#endif
}

// 1 - the volume's edge weight at footprint uv (1 outside the footprint, also with no edge fade).
float far_weight(vec2 uv) {
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;
    return 1.0 - cloud_edge_weight(uv, edge_fade);
}

// Distance along the ray to where it first reaches the far field: the edge fade's inner circle
// |2 uv - 1| = 1 - edge_fade (the footprint's edge without a fade); 0 when the camera is past it.
float far_entry(vec3 dir) {
    vec2 size = (layer_max - layer_min).xz;
    vec2 a = 2.0 * (camera_pos.xz - layer_min.xz) / size - 1.0, b = 2.0 * dir.xz / size;
    if (edge_fade <= 0.0) {                        // leave the square |a + s b|_inf = 1
        if (max(abs(a.x), abs(a.y)) >= 1.0) return 0.0;
        vec2 bb = mix(b, vec2(1e-12), lessThan(abs(b), vec2(1e-12)));
        vec2 tt = (sign(bb) - a) / bb;
        return min(tt.x, tt.y);
    }
    float r = 1.0 - edge_fade, bb = dot(b, b), ab = dot(a, b), aa = dot(a, a) - r * r;
    if (aa >= 0.0) return 0.0;
    if (bb < 1e-20) return 1e30;
    return (-ab + sqrt(max(ab * ab - bb * aa, 0.0))) / bb;
}

// Whether skip-map texel g holds no density: with a cloud type (shape.glsl) the whole column of texels
// above and below it, since the type spreads a column's density over the layer's height.
bool skip_empty(ivec3 g, ivec3 grid) {
    if (cloud_type < 0.0) return texelFetch(skip_map, g, 0).r <= 0.0;
    for (int y = 0; y < grid.y; ++y)
        if (texelFetch(skip_map, ivec3(g.x, y, g.z), 0).r > 0.0) return false;
    return true;
}

// Distance along the ray to where it leaves skip-map texel g (a box in world space; with a cloud type
// its whole column).
float skip_exit(ivec3 g, vec3 pos, vec3 inv_dir, vec3 dir) {
    vec3 lo = layer_min + vec3(g) * skip_cells * cell_size;
    vec3 hi = min(lo + skip_cells * cell_size, layer_max);
    if (cloud_type >= 0.0) {
        lo.y = layer_min.y;
        hi.y = march_max().y;
    }
    vec3 tt = (mix(lo, hi, step(0.0, dir)) - pos) * inv_dir;
    return max(min(min(tt.x, tt.y), tt.z), 0.0);
}

// The march through full-res pixel `pixel`: premultiplied (light, alpha = 1 - T) in `color`,
// (alpha * distance, alpha) in `distance`, the scene's window depth there in `depth`.
void cloud_march(ivec2 pixel, out vec4 color, out vec2 distance, out float depth) {
    vec2 uv = (vec2(pixel) + 0.5) / vec2(frame_size);
    depth = texelFetch(scene_depth, pixel, 0).r;
    vec3 dir = view_ray_dir(uv, view_basis);
    float scene = view_ray_distance(uv, depth, view_basis, near, far, 1e30);
    vec3 safe = mix(dir, vec3(1e-12), lessThan(abs(dir), vec3(1e-12)));
    vec3 inv_dir = 1.0 / safe;
    vec3 t0 = (layer_min - camera_pos) * inv_dir, t1 = (march_max() - camera_pos) * inv_dir;
    float start = near * length(view_ray(uv, view_basis));          // the near plane along this ray
    float enter = max(max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z)), start);
    float leave = min(min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z)), scene);
    float far_from = 1e30;                         // no far field: never reached
#if !MARCH_VOLUME
    leave = enter;                                 // the box is not marched: the far band alone
#endif
#if FAR_FIELD
    {   // the band's part beyond the far field's entry, joined to the box's (the box is inside the band)
        float b0 = (layer_min.y - camera_pos.y) * inv_dir.y, b1 = (march_max().y - camera_pos.y) * inv_dir.y;
        far_from = far_entry(dir);
        float fin = max(max(min(b0, b1), start), far_from);
        float fout = min(min(max(b0, b1), scene), far_distance);
        if (fout > fin) {
            bool box = leave > enter;
            enter = box ? min(enter, fin) : fin;
            leave = box ? max(leave, fout) : fout;
        }
    }
#endif
    vec3 light = vec3(0.0);
    float trans = 1.0, weighted = 0.0;
    if (leave > enter) {
        vec3 extent = layer_max - layer_min;
        float ny = extent.y / cell_size.y;
        ivec3 grid = textureSize(skip_map, 0);
        float u = sample_jitter(vec2(pixel));
        float eps = 1e-3 * min(min(cell_size.x, cell_size.y), cell_size.z);
        float s = enter;
        int taken = 0;
        for (int it = 0; it < steps + max_skips && taken < steps && s < leave; ++it) {
            vec3 pos = camera_pos + dir * s;
            bool far_zone = s >= far_from;
            if (skipping != 0 && !far_zone) {
                ivec3 g = clamp(ivec3(floor((pos - layer_min) / cell_size / skip_cells)), ivec3(0), grid - 1);
                if (skip_empty(g, grid)) {
                    s = min(s + skip_exit(g, pos, inv_dir, dir) + eps, max(far_from, s + eps));
                    continue;
                }
            }
            float growth = step_growth;
#if FAR_FIELD
            float fw = far_zone ? far_weight((pos.xz - layer_min.xz) / extent.xz) : 0.0;
            growth = mix(step_growth, far_growth, fw);
#endif
            float dt = min(step_base + growth * s, leave - s);
            float sp = s + u * dt;
            s += dt;
            ++taken;
            vec3 p = camera_pos + dir * sp;
            vec3 uvw = (p - layer_min) / extent;
            bool in_box = MARCH_VOLUME != 0 && in_march_box(uvw);
            float dv = in_box ? shaped_density(uvw, ny) : 0.0, df = 0.0;
#if FAR_FIELD
            vec4 fc = vec4(0.0);
            float fh = far_height(p.y);
            if (far_zone) {
                fw = far_weight((p.xz - layer_min.xz) / extent.xz);
                if (fw > 0.0) {
                    fc = far_ranks(p.xz, sp);
                    df = fw * far_density(fc.x, fh, ny, p.xz);
                }
            }
#endif
            float footprint = pixel_angle * sp;        // the full-res pixel's width here (detail.glsl)
            float d = detail_density(dv + df, p, footprint);
            if (d <= 0.0) continue;
            float a = 1.0 - exp(-sigma_t * d * dt);
            float w = trans * a;
            vec3 J = vec3(0.0);
            if (dv > 0.0) {
                float T = min(sun_transmittance(p, uvw, extent, footprint), 1.0);
                J = cloud_source_with(uvw, dir, ny, T);
            }
#if FAR_FIELD
            if (df > 0.0) J = mix(J, far_source(fc, fh, dir), df / (dv + df));
#endif
            light += w * min(J, vec3(HDR_MAX));   // lib/hdr_max.glsl (through volume.glsl)
            weighted += w * sp;
            trans *= 1.0 - a;
            if (trans < min_transmittance) break;
        }
    }
    float alpha = 1.0 - trans;
    color = vec4(light, alpha);
    distance = vec2(weighted, alpha);   // composited by its own alpha (atmos/composition.py)
}
