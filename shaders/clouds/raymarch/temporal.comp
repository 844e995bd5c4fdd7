#version 430
// The temporal resolve of the ray-marched clouds (plugins/clouds/raymarch/temporal.py says what and
// why; float64 reference: plugins/clouds/raymarch/temporal_reference.py). One compute invocation per
// full-res pixel stores the next history: colour (premultiplied), distance (a·d, a), the scene distance
// behind the pixel with the samples its colour averages, and its last marched sample. COMPOSITE 1: it
// also composites the colour, as stored (float16, read back), onto the frame's colour in place,
// premultiplied as blend_over did (rgb and alpha = history + (1 - a) · colour), and, COMPOSITE_DISTANCE
// 1, the distance onto "cloud_distance" with the same weights.
#include "lib/view_ray.glsl"
#include "lib/upsample.glsl"
#include "lib/over.glsl"

layout(binding = 0) uniform sampler2D low_color;      // this frame's samples: texel (i, j) = pixel (i·r + ox, j·r + oy)
layout(binding = 1) uniform sampler2D low_distance;
layout(binding = 2) uniform sampler2D hist_color;     // the previous frame's output, full res
layout(binding = 3) uniform sampler2D hist_distance;
layout(binding = 4) uniform sampler2D hist_scene;     // its scene distance (m), -1 = sky; the samples its colour averages
layout(binding = 5) uniform sampler2D scene_depth;    // this frame's depth (when has_depth)
layout(binding = 6) uniform sampler2D low_depth;      // the scene depth each sample's ray saw (edge < 1e30)
layout(binding = 7) uniform sampler2D hist_sample;    // each pixel's last marched sample (carried for drift.comp)
layout(binding = 8) uniform sampler2D drift;          // low-res: 1 where this frame's samples moved (drift.comp; detect_change)

uniform int r;
uniform bool has_depth;
uniform float edge;           // the depth-aware upsample's edge (offscreen.EDGE; 1e30: bilinear)
layout(std140, binding = 1) uniform Resolve {   // written once per resolve (temporal.py RESOLVE_BLOCK)
    mat3 view_basis;          //   0  this frame's rays (lib/view_ray.glsl)
    mat3 prev_proj;           //  48  v (m, relative to the previous camera) -> (clip x, clip y, clip w)
    vec3 cam_delta;           //  96  this camera's position - the previous one's
    float near;               // 108
    ivec2 offset;             // 112  the pixel marched in each r x r block
    float far;                // 120
    float history_clamp;      // 124
    float motion_limit;       // 128
    bool history_valid;       // 132
    bool still;               // 136  the camera did not change: the history is at this very pixel
    bool detect_change;       // 140  still for r² frames: every pixel's last sample is real, a change is the clouds'
};                            // 144 bytes

const float CLAMP_MOTION = 1.0;      // temporal.py's constants
const float DEPTH_TOLERANCE = 0.1;
const float ALPHA_EPS = 1e-4;
const float CHANGE_TOLERANCE = 0.02;
const float HISTORY_BLEND = 0.15;

layout(local_size_x = 8, local_size_y = 8) in;
#if COMPOSITE
layout(binding = 0, rgba16f) uniform image2D next_color;       // the history written (the other set), read back
#else
layout(binding = 0, rgba16f) uniform writeonly image2D next_color;     // the history written: the other set
#endif
layout(binding = 1, rg32f) uniform writeonly image2D next_distance;
layout(binding = 2, rg32f) uniform writeonly image2D next_scene;
layout(binding = 3, rgba16f) uniform writeonly image2D next_sample;
#if COMPOSITE
layout(binding = 4, rgba16f) uniform image2D color_image;             // the frame's colour
#endif
#if COMPOSITE_DISTANCE == 1
layout(binding = 5, rg32f) uniform image2D distance_image;            // the frame's "cloud_distance"
#elif COMPOSITE_DISTANCE == 2
layout(binding = 5, rg32f) writeonly uniform image2D distance_image;  // made here (its first writer)
#endif

// Bilinear sample of a colour and a distance texture at texel-centre coordinates p, clamped to the edge
// (done by hand: the same weights as the reference, whatever the texture's filter).
void bilinear2(sampler2D a, sampler2D b, vec2 p, out vec4 va, out vec2 vb) {
    ivec2 last = textureSize(a, 0) - 1;
    ivec2 p0 = ivec2(floor(p));
    vec2 f = p - vec2(p0);
    va = vec4(0.0); vb = vec2(0.0);
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 q = clamp(p0 + o, ivec2(0), last);
        vec2 w = mix(1.0 - f, f, vec2(o));
        va += w.x * w.y * texelFetch(a, q, 0);
        vb += w.x * w.y * texelFetch(b, q, 0).rg;
    }
}

// v relative to the previous camera (w = 1 a point, w = 0 a direction) -> previous texel coordinates;
// false when behind the previous camera.
bool project(vec3 v, vec2 size, out vec2 q) {
    vec3 c = prev_proj * v;
    if (c.z <= 0.0) { q = vec2(-1e9); return false; }
    q = (c.xy / c.z * 0.5 + 0.5) * size - 0.5;
    return true;
}

// The history at full-res pixel pix: colour, distance (a·d, a), (scene distance, samples averaged), last
// marched sample.
void resolve(ivec2 pix, vec2 size, out vec4 out_color, out vec2 out_distance, out vec2 out_scene, out vec4 out_sample) {
    vec2 uv = (vec2(pix) + 0.5) / size;
    vec3 dir = view_ray_dir(uv, view_basis);
    float scene = -1.0;
    if (has_depth) scene = view_ray_distance(uv, texelFetch(scene_depth, pix, 0).r, view_basis, near, far, -1.0);

    // a pixel marched this frame: its sample, averaged into its history below
    ivec2 rel = pix - offset;
    bool fresh = rel.x >= 0 && rel.y >= 0 && rel.x % r == 0 && rel.y % r == 0;
    vec4 fc = vec4(0.0); vec2 fd = vec2(0.0);
    if (fresh) {
        ivec2 q = min(rel / r, textureSize(low_color, 0) - 1);
        fc = texelFetch(low_color, q, 0);
        fd = texelFetch(low_distance, q, 0).rg;
    }
    // this frame's samples upsampled, and the box of the 3x3 low-res texels around the pixel
    vec2 lp = (vec2(pix) - vec2(offset)) / float(r);
    ivec2 last = textureSize(low_color, 0) - 1;
    ivec2 taps[4];
    float weights[4];
    float inv_pixel = upsample_inv_depth(has_depth ? texelFetch(scene_depth, pix, 0).r : 1.0, vec2(1.0 / near, 1.0 / far));
    upsample_taps(low_depth, last, lp, inv_pixel, vec2(1.0 / near, 1.0 / far), edge, taps, weights);
    vec4 c = vec4(0.0); vec2 d = vec2(0.0);
    for (int k = 0; k < 4; ++k) {
        c += weights[k] * texelFetch(low_color, taps[k], 0);
        d += weights[k] * texelFetch(low_distance, taps[k], 0).rg;
    }
    if (!history_valid) {
        out_color = fresh ? fc : c;
        out_distance = fresh ? fd : d;
        out_sample = out_color;
        out_scene = vec2(scene, fresh ? 1.0 : 0.0);
        return;
    }
    ivec2 centre = clamp(ivec2(floor(lp + 0.5)), ivec2(0), last);
    vec4 lo_c = vec4(1e30), hi_c = vec4(-1e30);
    vec2 lo_d = vec2(1e30), hi_d = vec2(-1e30);
    for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) {
            ivec2 q = clamp(centre + ivec2(i, j), ivec2(0), last);
            vec4 nc = texelFetch(low_color, q, 0);
            vec2 nd = texelFetch(low_distance, q, 0).rg;
            lo_c = min(lo_c, nc); hi_c = max(hi_c, nc);
            lo_d = min(lo_d, nd); hi_d = max(hi_d, nd);
        }

    // where this pixel's cloud was: by direction first, then at the distance the history holds there
    // (or, where it holds no cloud, the scene's)
    vec2 q = vec2(pix);
    bool inside = true;
    if (!still) {
        inside = project(dir, size, q);
        vec4 hc; vec2 hd;
        bilinear2(hist_color, hist_distance, q, hc, hd);
        // no cloud held there: the scene behind the pixel moves it (terrain), else it is sky at infinity
        float at = hd.y > ALPHA_EPS ? hd.x / hd.y : scene;
        if (inside && at > 0.0) inside = project(cam_delta + dir * at, size, q);
        inside = inside && all(greaterThanEqual(q, vec2(-0.5))) && all(lessThanEqual(q, size - 0.5));
    }
    float motion = length(q - vec2(pix));
    vec4 hc; vec2 hd;
    bilinear2(hist_color, hist_distance, q, hc, hd);
    ivec2 nearest = clamp(ivec2(floor(q + 0.5)), ivec2(0), ivec2(size) - 1);
    out_sample = texelFetch(hist_sample, nearest, 0);

    // disocclusion: the scene behind the pixel is not the one the history saw there
    float prev_scene = texelFetch(hist_scene, nearest, 0).r;
    float expected = scene < 0.0 ? -1.0 : length(cam_delta + dir * scene);
    bool same = (expected < 0.0) == (prev_scene < 0.0)
             && (expected < 0.0 || abs(prev_scene - expected) <= DEPTH_TOLERANCE * expected);
    if (!(inside && same)) out_sample = c;      // no last sample of this scene here: the upsample stands in

    // a still camera, every pixel's last sample real: where the clouds around the pixel drift (the
    // drift pass), has the image changed where it was marched? this frame's nearest sample against the
    // history there. Where they change in place (evolving), the history stays.
    float drifting = 0.0;
    if (detect_change)
        for (int k = 0; k < 9; ++k)
            drifting = max(drifting, texelFetch(drift, clamp(centre + ivec2(k % 3 - 1, k / 3 - 1), ivec2(0), last), 0).r);
    vec2 qf = vec2(centre * r + offset) + (q - vec2(pix));
    vec4 predicted = texelFetch(hist_color, clamp(ivec2(floor(qf + 0.5)), ivec2(0), ivec2(size) - 1), 0);
    vec4 now = texelFetch(low_color, centre, 0);
    vec3 drgb = abs(now.rgb - predicted.rgb);
    float change = drifting * max(abs(now.a - predicted.a),
                                  max(drgb.r, max(drgb.g, drgb.b)) / max(max(hi_c.r, max(hi_c.g, hi_c.b)), 1e-3));
    float moved = max(min(motion / CLAMP_MOTION, 1.0), min(change / CHANGE_TOLERANCE, 1.0));
    // correct the history by this frame's samples: their bilinear blend of (fresh - history at the
    // sample, moved like this pixel), with the upsample's depth-aware weights, so history and fresh
    // samples agree (no 2-pixel pattern)
    vec4 dc = vec4(0.0); vec2 dd = vec2(0.0);
    for (int k = 0; k < 4; ++k) {
        if (weights[k] == 0.0) continue;
        vec4 pc; vec2 pd;
        bilinear2(hist_color, hist_distance, vec2(taps[k] * r + offset) + (q - vec2(pix)), pc, pd);
        dc += weights[k] * (texelFetch(low_color, taps[k], 0) - pc);
        dd += weights[k] * (texelFetch(low_distance, taps[k], 0).rg - pd);
    }
    hc += moved * dc;
    hd += moved * dd;
    float clamp_w = history_clamp * (fresh ? 1.0 : moved);     // a marched pixel's mean: to this frame's box
    hc = mix(hc, clamp(hc, lo_c, hi_c), clamp_w);
    hd = mix(hd, clamp(hd, lo_d, hi_d), clamp_w);
    // what a layer can hold (the correction moves history by differences taken elsewhere): light and
    // a.d at least 0, coverage in [0, 1]
    hc = clamp(hc, vec4(0.0), vec4(vec3(3.4e38), 1.0));
    hd = clamp(hd, vec2(0.0), vec2(3.4e38, 1.0));
    // drifting clouds: the history is stale where its sample changed, the upsample of this frame's
    // samples is nearer (all of it from CHANGE_TOLERANCE, none below half)
    float trust = 1.0 - clamp(2.0 * change / CHANGE_TOLERANCE - 1.0, 0.0, 1.0);
    float keep = (inside && same) ? trust * clamp(1.0 - motion / motion_limit, 0.0, 1.0) : 0.0;
    // the samples the kept history averages (none where it moved, was dropped or the clouds drift)
    float held = texelFetch(hist_scene, nearest, 0).g * keep * (1.0 - moved) * (1.0 - drifting);
    if (fresh) {        // the running mean of its samples, then an exponential one (HISTORY_BLEND)
        float a = max(1.0 / (held + 1.0), HISTORY_BLEND);
        out_color = fc + (1.0 - a) * (hc - fc);                 // exact at a = 1
        out_distance = fd + (1.0 - a) * (hd - fd);
        out_sample = fc;
        out_scene = vec2(scene, min(held + 1.0, 1.0 / HISTORY_BLEND));
        return;
    }
    out_color = (1.0 - keep) * c + keep * hc;                 // not mix(): exact at keep = 1
    out_distance = (1.0 - keep) * d + keep * hd;
    out_scene = vec2(scene, held);
}

void main() {
    ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
    ivec2 extent = imageSize(next_color);
    if (any(greaterThanEqual(pix, extent))) return;
    vec4 color, last; vec2 distance, scene;
    resolve(pix, vec2(extent), color, distance, scene, last);
    imageStore(next_color, pix, color);
    imageStore(next_distance, pix, vec4(distance, 0.0, 0.0));
    imageStore(next_scene, pix, vec4(scene, 0.0, 0.0));
    imageStore(next_sample, pix, last);
#if COMPOSITE
    vec4 held = imageLoad(next_color, pix);     // as stored (float16, rounded as the GL rounds): this invocation's own write
    imageStore(color_image, pix, over(held, imageLoad(color_image, pix)));
#endif
#if COMPOSITE_DISTANCE == 1
    imageStore(distance_image, pix, vec4(over(distance, imageLoad(distance_image, pix).rg), 0.0, 0.0));
#elif COMPOSITE_DISTANCE == 2
    imageStore(distance_image, pix, vec4(distance, 0.0, 0.0));    // what over() onto the clear (0, 0) gives
#endif
}
