#version 430
// Temporal anti-aliasing (plugins/antialias/temporal.py): the scene's geometry is drawn a sub-pixel off
// each frame (lib/frame.glsl jitter_clip) and each pixel blends this frame's colour over the history
// (the last output) read where the pixel's point was in the previous frame: the nearest depth of its 3x3
// neighbourhood (edges follow the object in front) gives the point, or the ray's direction where it sees
// the sky; prev_view_proj (unjittered) projects it. With MOTION defined, a moving surface's own motion
// (atmos.render_core.MotionTargets: world motion since the last frame, tagged with its depth) is taken
// off the point first where the tag matches that depth. The history is clamped to the neighbourhood's colour
// range (what it shows now) and the two are weighted by 1 / (1 + luma) (Karis 2014: a bright sample does
// not flicker through), the newest with at least `blend`, more as the point moves (MOTION_GAIN); the
// history is read by Catmull-Rom. Off the previous view, or with no history: the
// frame's own colour. Alpha (the sky occlusion) is this frame's. taa_copy.comp then writes the result
// (the next frame's history) into the frame's colour. float64 twin: plugins/antialias/reference.py
// taa_resolve.
#include "lib/frame.glsl"
#include "lib/view_ray.glsl"
#include "lib/catmull_rom.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D color_in;        // this frame's HDR colour (texelFetch)
layout(binding = 1) uniform sampler2D depth_in;        // its depth (texelFetch)
layout(binding = 2) uniform sampler2D history;         // the last output (texelFetch: history_at)
#ifdef MOTION
layout(binding = 3) uniform sampler2D motion_in;       // (world motion, depth tag); alpha -1: none (texelFetch)
const float MOTION_DEPTH_TOLERANCE = 1.0 / 8388608.0;  // two steps of a 24-bit depth (render_core.py)
#endif
layout(binding = 0, rgba16f) writeonly uniform image2D resolved;     // kept: the next frame's history
layout(std140, binding = 1) uniform TemporalAA {       // written once per frame (temporal.py TAA_BINDING)
    mat4 prev_view_proj;       // the previous frame's view_proj (no jitter)
    float blend;               // the newest frame's least weight
    int has_history;
};

// The history at uv by Catmull-Rom over its 4x4 nearest texels (clamped to the edge): sharper than a
// bilinear read, which would blur a moving view a little more every frame.
vec3 history_at(vec2 uv) {
    ivec2 size = textureSize(history, 0);
    vec2 t = uv * vec2(size) - 0.5;
    ivec2 base = ivec2(floor(t));
    vec2 f = t - floor(t);
    vec4 wx = catmull_rom_weights(f.x), wy = catmull_rom_weights(f.y);
    vec3 sum = vec3(0.0);
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 4; ++x) {
            ivec2 q = clamp(base + ivec2(x - 1, y - 1), ivec2(0), size - 1);
            sum += wx[x] * wy[y] * texelFetch(history, q, 0).rgb;
        }
    }
    return sum;
}

// The newest frame's weight grows by this much per pixel the point moved since the previous frame (each
// resampling of the history softens it: turning 2.7 px a frame, 0.2 keeps the error to a supersampled
// view at 1.0 % where a fixed weight leaves 1.2 %; benchmarks/bench_antialias.py).
const float MOTION_GAIN = 0.2;

float taa_luma(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(color_in, 0);
    if (any(greaterThanEqual(p, size))) return;
    vec4 now = texelFetch(color_in, p, 0);
    vec3 lo = now.rgb, hi = now.rgb;
    float depth = texelFetch(depth_in, p, 0).r;
    ivec2 nearest = p;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = clamp(p + ivec2(dx, dy), ivec2(0), size - 1);
            vec3 c = texelFetch(color_in, q, 0).rgb;
            lo = min(lo, c);
            hi = max(hi, c);
            float d = texelFetch(depth_in, q, 0).r;
            if (d < depth) {
                depth = d;
                nearest = q;
            }
        }
    }
    vec3 color = now.rgb;
    if (has_history != 0) {
        vec3 ray = view_ray((vec2(p) + 0.5) / vec2(size), view_basis);
        vec3 point = camera_pos + view_depth(depth, near, far) * ray;
#ifdef MOTION
        vec4 m = texelFetch(motion_in, nearest, 0);
        if (abs(m.a - depth) <= MOTION_DEPTH_TOLERANCE) point -= m.xyz;
#endif
        vec4 clip = depth < 1.0 ? prev_view_proj * vec4(point, 1.0) : prev_view_proj * vec4(ray, 0.0);
        if (clip.w > 0.0) {
            vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
            if (all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)))) {
                vec3 past = clamp(history_at(uv), lo, hi);
                float moved = length((uv - (vec2(p) + 0.5) / vec2(size)) * vec2(size));
                float a = max(blend, min(moved * MOTION_GAIN, 1.0));
                float wn = a / (1.0 + taa_luma(now.rgb)), wp = (1.0 - a) / (1.0 + taa_luma(past));
                color = (now.rgb * wn + past * wp) / (wn + wp);
            }
        }
    }
    imageStore(resolved, p, vec4(color, now.a));
}
