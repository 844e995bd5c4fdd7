// Shared by the true-path shear-warp's two kernels (shear_warp.comp: the columns; shear_warp_rays.comp: the
// cells that march their own ray); float64 twin: plugins/clouds/light/reference.py (_step_depth, bends).
#include "clouds/light/sample.glsl"

const float TAU_MAX = 1e30;

layout(binding = 0) uniform sampler3D density;                         // shading grid, texelFetch only
layout(RESULT_FORMAT, binding = 2) uniform writeonly image3D result;

layout(std140, binding = 1) uniform Columns {
    ivec4 grid;        // shading grid (x, y, z); slices along the slicing axis
    ivec4 axes;        // slicing axis, the two lateral axes (0 x, 1 y, 2 z); +1 where the sun is toward +axis
    ivec4 columns;     // first column (lateral b, c); slices [i0, i1) of this run (k-th from the light side)
    vec4 light;        // v (b, c): the lateral step toward the sun per slice; one step's true length in fine cells; sigma
};

ivec2 lateral_size() { return ivec2(grid[axes.y], grid[axes.z]); }

int slice_of(int k) { return axes.w > 0 ? grid.w - 1 - k : k; }

vec3 grid_point(float slice, vec2 lateral) {
    vec3 p;
    p[axes.x] = slice;
    p[axes.y] = lateral.x;
    p[axes.z] = lateral.y;
    return p;
}

// rho at t of the step toward the sun from lateral p on the k-th slice (t = 1: the slice before)
float rho_at(int k, vec2 p, float t) {
    return shading_trilinear(density, grid.xyz, grid_point(float(slice_of(k)) + t * float(axes.w), p + t * light.xy));
}

// the part [lo, hi] of that step inside the box (half a step from the light-side slice); empty: hi <= lo
vec2 inside_part(int k, vec2 p, ivec2 n) {
    vec2 v = light.xy;
    float lo = 0.0, hi = k == 0 ? 0.5 : 1.0;
    for (int i = 0; i < 2; ++i) {
        if (v[i] != 0.0) {
            float t0 = (-0.5 - p[i]) / v[i], t1 = (float(n[i]) - 0.5 - p[i]) / v[i];
            lo = max(lo, min(t0, t1));
            hi = min(hi, max(t0, t1));
        } else if (p[i] < -0.5 || p[i] > float(n[i]) - 0.5) {
            hi = -1.0;
        }
    }
    return vec2(lo, hi);
}

float step_depth(vec2 part, float rho0, float rho1) {          // sigma = 0 gives exactly 0, never 0 * inf
    return (light.w * (0.5 * rho0 + 0.5 * rho1)) * ((part.y - part.x) * light.z);
}

// whether cell c of the k-th slice (taps at fraction f) marches its own ray (reference.bends): a tap beyond
// a face along an axis with v != 0, or taps that leave the box toward the sun through different faces
bool bends(int k, ivec2 c, vec2 f, ivec2 n) {
    vec2 v = light.xy;
    float light_side = float(k) + 0.5;
    vec2 low = vec2(1e38), high = vec2(1e38);        // exits through the lateral sun-facing faces (none: never)
    for (int i = 0; i < 2; ++i) {
        if (v[i] == 0.0) continue;
        float first = float(c[i]) - 1.0 - f[i], last = float(c[i]) + 2.0 - f[i];
        if (first < -0.5 || last > float(n[i]) - 0.5) return true;
        float face = v[i] > 0.0 ? float(n[i]) - 0.5 : -0.5;
        float e0 = (face - first) / v[i], e1 = (face - last) / v[i];
        low[i] = min(e0, e1);
        high[i] = max(e0, e1);
    }
    bool one_face = light_side < min(low.x, low.y)
                 || (v.x != 0.0 && high.x < min(light_side, low.y))
                 || (v.y != 0.0 && high.y < min(light_side, low.x));
    return !one_face;
}
