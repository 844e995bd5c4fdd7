#version 430
// Density maps, pass 2 (thesis 7.2.2): the max of every sum map over each sprite-group segment
// x in [gx * u_group.x, min((gx + 1) * u_group.x, nx)) (same for z), for segment rows
// gz = u_gz0 + gl_GlobalInvocationID.y and layer gl_GlobalInvocationID.z.
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0) uniform sampler2DArray u_sums;            // (nx, nz, layers), r32f
layout(binding = 0, r32f) uniform writeonly image2DArray u_max;    // (gx, gz, layers)

uniform ivec2 u_extent;                   // nx, nz
uniform ivec2 u_group;                    // segment size in cells (x, z)
uniform ivec2 u_grid;                     // gx, gz
uniform int u_gz0;

void main() {
    ivec3 seg = ivec3(gl_GlobalInvocationID.x, int(gl_GlobalInvocationID.y) + u_gz0, gl_GlobalInvocationID.z);
    if (seg.x >= u_grid.x || seg.y >= u_grid.y) return;
    ivec2 lo = seg.xy * u_group;
    ivec2 hi = min(lo + u_group, u_extent);
    float m = 0.0;
    for (int z = lo.y; z < hi.y; ++z) {
        for (int x = lo.x; x < hi.x; ++x) {
            m = max(m, texelFetch(u_sums, ivec3(x, z, seg.z), 0).r);
        }
    }
    imageStore(u_max, seg, vec4(m));
}
