#version 430
// Density maps, pass 1 (thesis 7.2.2): for each column (x, z), z = z0 + gl_GlobalInvocationID.y,
// layer 0 = sum of the density over all heights, layer 1 + b = sum over heights
// [b * u_band_height, min((b + 1) * u_band_height, ny)). float32 sums of non-negative values.
layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

layout(binding = 0) uniform sampler3D u_density;              // (nx, ny, nz), r16f or r32f
layout(binding = 0, r32f) uniform writeonly image2DArray u_sums;   // (nx, nz, bands + 1)

uniform ivec3 u_size;
uniform int u_band_height;
uniform int u_z0;

void main() {
    ivec2 column = ivec2(gl_GlobalInvocationID.x, int(gl_GlobalInvocationID.y) + u_z0);
    if (column.x >= u_size.x || column.y >= u_size.z) return;
    float total = 0.0;
    for (int y0 = 0, band = 1; y0 < u_size.y; y0 += u_band_height, ++band) {
        float s = 0.0;
        for (int y = y0; y < min(y0 + u_band_height, u_size.y); ++y) {
            s += texelFetch(u_density, ivec3(column.x, y, column.y), 0).r;
        }
        imageStore(u_sums, ivec3(column, band), vec4(s));
        total += s;
    }
    imageStore(u_sums, ivec3(column, 0), vec4(total));
}
