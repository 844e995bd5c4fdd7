#version 430
// The light volume's columns (plugins/clouds/light/columns.py; float64 twin: columns.column_reference): per cell
// of the shading grid, the integral of the fine density straight up to the volume's top face (r) and
// straight down to its bottom face (g), in fine cells of density 1 (the renderers multiply by
// sigma_t * cell height). The density is trilinear between fine cell centres, clamped in the outer half
// cells, so along y at a coarse cell's (x, z) it is piecewise linear: trapezoids between fine rows, exact.
// One invocation per coarse (x, z) column; the slice range [z0, ...) is over z.
layout(local_size_x = 8, local_size_y = 8) in;
#include "clouds/light/sample.glsl"
layout(binding = 0) uniform sampler3D fine;
uniform ivec3 fine_size;
uniform int z0;                // first coarse z cell of this slice
layout(rg16f, binding = 0) uniform writeonly image3D columns;
const float STORE_MAX = 65000.0;   // rg16f's range: an optical depth this large is opaque anyway

float row(vec2 lateral, int j) {           // the fine density at (x, z) = lateral, fine row y = j
    return shading_trilinear(fine, fine_size, vec3(lateral.x, float(j), lateral.y));
}

void main() {
    ivec3 n = imageSize(columns);
    ivec2 q = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, z0);
    if (q.x >= n.x || q.y >= n.z) return;
    vec3 h3 = vec3(fine_size) / vec3(n);
    float h = h3.y;
    vec2 lateral = (vec2(q) + 0.5) * h3.xz - 0.5;
    int ny = fine_size.y;
    float total = 0.5 * row(lateral, 0) + 0.5 * row(lateral, ny - 1);   // the two outer half cells
    for (int j = 0; j + 1 < ny; ++j)
        total += 0.5 * (row(lateral, j) + row(lateral, j + 1));
    float below = 0.5 * row(lateral, 0);       // F(j): the integral from the bottom face to row j
    int j = 0;
    for (int k = 0; k < n.y; ++k) {
        float yc = (float(k) + 0.5) * h - 0.5;
        while (j + 1 < ny && float(j + 1) <= yc) {
            below += 0.5 * (row(lateral, j) + row(lateral, j + 1));
            ++j;
        }
        float r0 = row(lateral, j), f = yc - float(j), down;
        if (yc < 0.0) down = r0 * (yc + 0.5);
        else if (j + 1 >= ny) down = below + r0 * f;
        else down = below + f * r0 + 0.5 * f * f * (row(lateral, j + 1) - r0);
        float up = max(total - down, 0.0);
        imageStore(columns, ivec3(q.x, k, q.y), vec4(min(up, STORE_MAX), min(max(down, 0.0), STORE_MAX), 0.0, 0.0));
    }
}
