#version 430
// The cells of the true-path shear-warp that the columns' warp cannot interpolate (bends(): a tap beyond a
// face, or taps whose rays leave the box through different faces): each marches its own ray toward the sun,
// by the columns' steps (plugins/clouds/light/shear_warp.py; float64 twin: reference.shear_warp_scheme).
// One invocation per cell the columns listed in Band (an indirect dispatch whose size they wrote).
layout(local_size_x = 64) in;
#include "clouds/light/shear_warp.glsl"

layout(std430, binding = 0) readonly buffer Band {
    uvec4 band_args;           // groups of 64, 1, 1; cells listed
    uvec2 band[];              // (x | y << 16, k)
};

void main() {
    uint index = gl_GlobalInvocationID.x;
    if (index >= min(band_args.w, uint(band.length()))) return;
    uvec2 entry = band[index];
    ivec2 n = lateral_size();
    ivec2 cell = ivec2(entry.x & 0xffffu, entry.x >> 16);
    int k = int(entry.y);
    vec2 v = light.xy;
    float depth = 0.0, rho_next = -1.0;          // rho at the start of the next step (< 0: not known)
    for (int back = 0; back <= k; ++back) {
        int kk = k - back;
        vec2 p = vec2(cell) + float(back) * v;
        vec2 part = inside_part(kk, p, n);
        if (part.y <= part.x) break;             // left the box (it is convex: for good)
        float r0 = part.x == 0.0 && rho_next >= 0.0 ? rho_next : rho_at(kk, p, part.x);
        float r1 = rho_at(kk, p, part.y);
        depth = min(depth + step_depth(part, r0, r1), TAU_MAX);
        if (part.y < 1.0) break;
        rho_next = r1;
    }
    imageStore(result, ivec3(grid_point(float(slice_of(k)), vec2(cell))), vec4(exp(-depth)));
}
