#version 430
// Drifting clouds under a still camera (plugins/clouds/raymarch/temporal.py says why; float64 twin:
// temporal_reference.drift_flags). One compute invocation per low-res texel: flag n is 1 where this frame's 3x3
// samples around it moved since they were last marched (r² frames ago, same pixels), i.e. a shift of
// one texel either way matches them better than none does, or where they changed by more than
// DRIFT_MEAN on average or one by more than DRIFT_CHANGE (a drift too fast for the shifts); 0 where they changed in place (clouds evolving) or not at all. A sample whose scene
// changed (an object moved in front, or away: the resolve rejects it there) takes no part.
#include "lib/view_ray.glsl"
layout(binding = 0) uniform sampler2D low_color;     // this frame's samples: texel m = pixel m·r + offset
layout(binding = 1) uniform sampler2D hist_sample;   // each full-res pixel's last marched sample
layout(binding = 2) uniform sampler2D scene_depth;   // this frame's depth (when has_depth)
layout(binding = 3) uniform sampler2D hist_scene;    // the history's scene distance (m), -1 = sky

uniform mat3 view_basis;
uniform float near, far;
uniform bool has_depth;

uniform int r;
uniform ivec2 offset;

const float DRIFT_GAIN = 0.3;      // temporal.py's constants
const float DRIFT_CHANGE = 0.4;
const float DRIFT_FLOOR = 0.1;
const float DRIFT_MEAN = 0.15;
const float DEPTH_TOLERANCE = 0.1;

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r8) uniform writeonly image2D flags;   // low-res, the size of low_color

// the change measure: alpha, and rgb relative to the neighbourhood's brightest channel
float change(vec4 a, vec4 b, float scale) {
    vec3 d = abs(a.rgb - b.rgb);
    return max(abs(a.a - b.a), max(d.r, max(d.g, d.b)) / scale);
}

// whether the scene behind full-res pixel p is the one the history saw there (the camera is still)
bool same_scene(ivec2 p, vec2 size) {
    float scene = -1.0;
    if (has_depth)
        scene = view_ray_distance((vec2(p) + 0.5) / size, texelFetch(scene_depth, p, 0).r, view_basis, near, far, -1.0);
    float prev = texelFetch(hist_scene, p, 0).r;
    return (scene < 0.0) == (prev < 0.0) && (scene < 0.0 || abs(prev - scene) <= DEPTH_TOLERANCE * scene);
}

void main() {
    ivec2 n = ivec2(gl_GlobalInvocationID.xy);
    ivec2 last = textureSize(low_color, 0) - 1;
    if (any(greaterThan(n, last))) return;
    ivec2 size = textureSize(hist_sample, 0);
    float scale = 1e-3;
    for (int j = -2; j <= 2; ++j)
        for (int i = -2; i <= 2; ++i) {
            vec3 c = texelFetch(low_color, clamp(n + ivec2(i, j), ivec2(0), last), 0).rgb;
            scale = max(scale, max(c.r, max(c.g, c.b)));
        }
    vec4 now[9];
    bool part[9];
    for (int k = 0; k < 9; ++k) {
        ivec2 m = clamp(n + ivec2(k % 3 - 1, k / 3 - 1), ivec2(0), last);
        now[k] = texelFetch(low_color, m, 0);
        part[k] = same_scene(min(m * r + offset, size - 1), vec2(size));
    }
    float still_cost = 0.0, largest = 0.0, best = 1e30;
    for (int u = 0; u < 9; ++u) {
        ivec2 shift = ivec2(u % 3 - 1, u / 3 - 1);
        float cost = 0.0;
        for (int k = 0; k < 9; ++k) {
            ivec2 m = clamp(clamp(n + ivec2(k % 3 - 1, k / 3 - 1), ivec2(0), last) + shift, ivec2(0), last);
            if (!part[k]) continue;
            float c = change(now[k], texelFetch(hist_sample, min(m * r + offset, size - 1), 0), scale);
            cost += c;
            if (u == 4) largest = max(largest, c);
        }
        if (u == 4) still_cost = cost;
        else best = min(best, cost);
    }
    float gain = (still_cost - min(best, still_cost)) / max(still_cost, 1e-6);
    bool drift = (gain > DRIFT_GAIN && still_cost > 9.0 * DRIFT_FLOOR) || still_cost > 9.0 * DRIFT_MEAN
              || largest > DRIFT_CHANGE;
    imageStore(flags, n, vec4(drift ? 1.0 : 0.0, 0.0, 0.0, 0.0));
}
