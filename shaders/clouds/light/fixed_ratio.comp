#version 430
// One slice of the thesis's fixed-ratio shear-warp (plugins/clouds/light/shear_warp.py, model "fixed-ratio";
// float64 twin: reference.shear_warp_scheme(fixed_ratio=True)): T = T_prev(q + step) * exp(-sigma * rho),
// bilinear in the previous slice, rounded to LEVELS steps (0: not rounded). Kept for comparison with the
// true-path columns of shear_warp.comp.
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
uniform float sigma;

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

void main() {
    ivec2 n = ivec2(dot(size, axis_b), dot(size, axis_c));
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (q.x >= n.x || q.y >= n.y) return;
    ivec3 cell = axis_a * slice + axis_b * q.x + axis_c * q.y;
    vec2 v = vec2(dot(step_dir, vec3(axis_b)), dot(step_dir, vec3(axis_c)));
    float value = 1.0;
    if (first == 0) {
        value = previous_transmittance(vec2(q) + v, n) * exp(-sigma * shading_trilinear(density, size, vec3(cell) + step_dir));
        if (LEVELS > 0) value = floor(value * float(LEVELS) + 0.5) / float(LEVELS);
    }
    imageStore(next_slice, q, vec4(value));
    imageStore(result, cell, vec4(value));
}
