#version 430
// Region volume, pass 1 of 2: every work item is one ellipsoid and one chunk of CHUNK cells of
// its (volume-clipped, CPU-computed) bounding box; each cell inside the ellipsoid gets
// atomicMax(value bits). Values are >= 0, so the order of their float bits as uints is the order
// of the floats: atomicMax on the bits is a max over ellipsoids (the thesis's MAX blending).
// value = 1 - r, r the normalized ellipsoid distance of the cell centre (see clouds/weather/reference.py).
#ifndef CHUNK
#define CHUNK 256
#endif
layout(local_size_x = 64) in;

struct Ellipsoid {
    vec4 center;      // xyz: centre in volume-local cells
    vec4 inv_radius;  // xyz: 1 / radius
    vec4 rotation;    // x: cos(yaw), y: sin(yaw)
};
layout(std430, binding = 0) readonly buffer Ellipsoids { Ellipsoid ellipsoids[]; };
layout(std430, binding = 1) readonly buffer Boxes { ivec4 boxes[]; };   // [2e]: lo.xyz, cells; [2e+1]: extent.xyz
layout(std430, binding = 2) readonly buffer Items { ivec2 items[]; };   // (ellipsoid, first cell of the chunk)
layout(std430, binding = 3) buffer Region { uint cells[]; };            // x fastest, then y, then z

uniform ivec3 size;
uniform int item_count;
uniform int groups_x;

void main() {
    int item = int(gl_WorkGroupID.y) * groups_x + int(gl_WorkGroupID.x);
    if (item >= item_count) return;
    ivec2 it = items[item];
    Ellipsoid e = ellipsoids[it.x];
    ivec4 lo = boxes[2 * it.x];
    ivec3 ext = boxes[2 * it.x + 1].xyz;
    int end = min(it.y + CHUNK, lo.w);
    float cs = e.rotation.x, sn = e.rotation.y;
    for (int i = it.y + int(gl_LocalInvocationID.x); i < end; i += 64) {
        ivec3 q = lo.xyz + ivec3(i % ext.x, (i / ext.x) % ext.y, i / (ext.x * ext.y));
        vec3 d = vec3(q) + 0.5 - e.center.xyz;
        vec3 n = vec3(cs * d.x + sn * d.z, d.y, -sn * d.x + cs * d.z) * e.inv_radius.xyz;
        float v = 1.0 - sqrt(dot(n, n));
        if (v > 0.0) {
            atomicMax(cells[q.x + size.x * (q.y + size.y * q.z)], floatBitsToUint(v));
        }
    }
}
