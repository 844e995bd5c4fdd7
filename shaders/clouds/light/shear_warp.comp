#version 430
// One slice of the inverse shear-warp (plugins/shading/shear_warp.py; float64 twin: reference.shear_warp_scheme).
// Voxel q of slice `slice`: optical depth = previous slice's (bicubic, limited, at q + step) + sigma *
// trapezoid of the density over the true path length of the step; partial step where the ray leaves.
// FIXED_RATIO: the thesis's model (T = T_prev(q + step) * exp(-sigma * rho), bilinear, LEVELS rounding).
layout(local_size_x = 8, local_size_y = 8) in;
#include "clouds/light/sample.glsl"

layout(binding = 0) uniform sampler3D density;                         // shading grid, texelFetch only
layout(r32f, binding = 0) uniform readonly image2D prev_slice;
layout(r32f, binding = 1) uniform writeonly image2D next_slice;
layout(RESULT_FORMAT, binding = 2) uniform writeonly image3D result;

uniform ivec3 size;            // shading grid (x, y, z)
uniform ivec3 axis_a;          // unit vectors: slicing axis and the two lateral axes
uniform ivec3 axis_b;
uniform ivec3 axis_c;
layout(std140, binding = 1) uniform Slice {   // one record per (slice, first), bound per dispatch
    int slice;
    int first;                 // 1 on the light-side slice (no previous slice)
};
uniform vec3 step_dir;         // index-space step toward the sun, component along axis_a = +-1
uniform float step_len;        // its true length in fine cells
uniform float sigma;

const float TAU_MAX = 1e30;

float exit_fraction(float q, float v, int n) {
    if (v > 0.0) return (float(n) - 0.5 - q) / v;
    if (v < 0.0) return (q + 0.5) / -v;
    return 1e30;
}

// lateral tap: odd mirror beyond the sun-facing face, clamp on the other side (reference.taps)
int tap(int i, int n, float v, out float s) {
    s = 1.0;
    if (v > 0.0 && i > n - 1) { i = 2 * n - 1 - i; s = -1.0; }
    if (v < 0.0 && i < 0) { i = -1 - i; s = -1.0; }
    return clamp(i, 0, n - 1);
}

vec4 catmull_rom(float t) {
    float t2 = t * t, t3 = t2 * t;
    return 0.5 * vec4(-t3 + 2.0 * t2 - t, 3.0 * t3 - 5.0 * t2 + 2.0, -3.0 * t3 + 4.0 * t2 + t, t3 - t2);
}

#ifndef FIXED_RATIO
float previous_depth(vec2 y, ivec2 n, vec2 v) {
    vec2 fl = floor(y);
    vec2 t = y - fl;
    ivec2 i0 = ivec2(fl);
    vec4 wa = catmull_rom(t.x), wb = catmull_rom(t.y);
    float sum = 0.0, lo = 1e38, hi = -1e38;
    for (int k = 0; k < 4; ++k) {
        float sb;
        int ib = tap(i0.y + k - 1, n.y, v.y, sb);
        for (int i = 0; i < 4; ++i) {
            float sa;
            int ia = tap(i0.x + i - 1, n.x, v.x, sa);
            float value = imageLoad(prev_slice, ivec2(ia, ib)).r * sa * sb;
            sum += wa[i] * wb[k] * value;
            if (i == 1 || i == 2) {
                if (k == 1 || k == 2) { lo = min(lo, value); hi = max(hi, value); }
            }
        }
    }
    return max(clamp(sum, lo, hi), 0.0);
}
#else
float previous_transmittance(vec2 y, ivec2 n) {
    y = clamp(y, vec2(0.0), vec2(n - 1));
    vec2 fl = floor(y);
    vec2 t = y - fl;
    ivec2 i0 = ivec2(fl);
    ivec2 i1 = min(i0 + 1, n - 1);
    float a = shading_lerp(imageLoad(prev_slice, i0).r, imageLoad(prev_slice, ivec2(i0.x, i1.y)).r, t.y);
    float b = shading_lerp(imageLoad(prev_slice, ivec2(i1.x, i0.y)).r, imageLoad(prev_slice, i1).r, t.y);
    return shading_lerp(a, b, t.x);
}
#endif

void main() {
    ivec2 n = ivec2(dot(size, axis_b), dot(size, axis_c));
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (q.x >= n.x || q.y >= n.y) return;
    ivec3 cell = axis_a * slice + axis_b * q.x + axis_c * q.y;
    vec3 p = vec3(cell);
    vec2 v = vec2(dot(step_dir, vec3(axis_b)), dot(step_dir, vec3(axis_c)));
    vec2 y = vec2(q) + v;
#ifdef FIXED_RATIO
    float value = 1.0;
    if (first == 0) {
        value = previous_transmittance(y, n) * exp(-sigma * shading_trilinear(density, size, p + step_dir));
        if (LEVELS > 0) value = floor(value * float(LEVELS) + 0.5) / float(LEVELS);
    }
    float transmittance = value;
#else
    float f = first != 0 ? 0.5 : 1.0;
    f = min(f, min(exit_fraction(float(q.x), v.x, n.x), exit_fraction(float(q.y), v.y, n.y)));
    bool full = f >= 1.0;
    float g = full ? 1.0 : f;
    float rho = 0.5 * min(texelFetch(density, cell, 0).r, 1e37) + 0.5 * shading_trilinear(density, size, p + g * step_dir);
    float value = (sigma * rho) * (g * step_len);      // sigma = 0 gives exactly 0, never 0 * inf
    if (full) value += previous_depth(y, n, v);
    value = min(value, TAU_MAX);
    float transmittance = exp(-value);
#endif
    imageStore(next_slice, q, vec4(value));
    imageStore(result, cell, vec4(transmittance));
}
