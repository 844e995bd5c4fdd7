// Clamp-to-edge trilinear sampling of a scalar volume with texelFetch (float weights, no filter state,
// no 8-bit sub-texel weight rounding). Index space: voxel i is centred at i. lerp(a, b, t) = a + (b-a)t
// keeps constants exact (a volume of ones samples to exactly 1). Results are capped at 1e37 so that sums of two
// samples stay finite (sigma = 0 then gives exactly 0, never 0 * inf).

float shading_lerp(float a, float b, float t) { return a + (b - a) * t; }

float shading_trilinear(sampler3D tex, ivec3 n, vec3 p) {
    p = clamp(p, vec3(0.0), vec3(n - 1));
    vec3 fl = floor(p);
    vec3 t = p - fl;
    ivec3 i0 = ivec3(fl);
    ivec3 i1 = min(i0 + 1, n - 1);
    float c00 = shading_lerp(texelFetch(tex, ivec3(i0.x, i0.y, i0.z), 0).r, texelFetch(tex, ivec3(i1.x, i0.y, i0.z), 0).r, t.x);
    float c10 = shading_lerp(texelFetch(tex, ivec3(i0.x, i1.y, i0.z), 0).r, texelFetch(tex, ivec3(i1.x, i1.y, i0.z), 0).r, t.x);
    float c01 = shading_lerp(texelFetch(tex, ivec3(i0.x, i0.y, i1.z), 0).r, texelFetch(tex, ivec3(i1.x, i0.y, i1.z), 0).r, t.x);
    float c11 = shading_lerp(texelFetch(tex, ivec3(i0.x, i1.y, i1.z), 0).r, texelFetch(tex, ivec3(i1.x, i1.y, i1.z), 0).r, t.x);
    return min(shading_lerp(shading_lerp(c00, c10, t.y), shading_lerp(c01, c11, t.y), t.z), 1e37);
}
