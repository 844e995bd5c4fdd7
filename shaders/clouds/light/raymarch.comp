#version 430
// Per-voxel ray march toward the sun, exact for trilinear density: the ray from a voxel centre crosses the
// integer planes (trilinear pieces) and half-integer planes (box faces) of axis a at m / (2|u_a|); between
// two crossings the density along the ray is cubic, integrated exactly by 2-point Gauss-Legendre.
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
#include "clouds/light/sample.glsl"
layout(binding = 0) uniform sampler3D density;
layout(RESULT_FORMAT, binding = 0) uniform writeonly image3D result;
uniform vec3 sun_dir;          // unit, index space
uniform float sigma;

void main() {
    ivec3 n = textureSize(density, 0);
    ivec3 cell = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(cell, n))) return;
    vec3 p = vec3(cell);
    vec3 u = sun_dir;
    vec3 au = abs(u);
    vec3 spacing = vec3(1e30);          // distance between successive plane crossings per axis
    float t_exit = 1e30;
    for (int a = 0; a < 3; ++a) {
        if (au[a] > 0.0) {
            spacing[a] = 0.5 / au[a];
            float d = u[a] > 0.0 ? float(n[a]) - 0.5 - p[a] : p[a] + 0.5;
            t_exit = min(t_exit, d / au[a]);
        }
    }
    const float G = 0.28867513459481287;   // 0.5 / sqrt(3)
    vec3 k = vec3(1.0);
    float t = 0.0, tau = 0.0;
    int limit = 2 * (n.x + n.y + n.z) + 8;
    for (int it = 0; it < limit && t < t_exit; ++it) {
        vec3 tn = k * spacing;
        float t1 = min(min(min(tn.x, tn.y), tn.z), t_exit);
        float mid = 0.5 * (t + t1), len = t1 - t;
        float rho = 0.5 * shading_trilinear(density, n, p + (mid - G * len) * u)
                  + 0.5 * shading_trilinear(density, n, p + (mid + G * len) * u);
        tau = min(tau + (sigma * rho) * len, 1e30);
        k += vec3(lessThanEqual(tn, vec3(t1)));
        t = t1;
    }
    imageStore(result, cell, vec4(exp(-tau)));
}
