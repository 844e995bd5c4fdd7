#version 430
// Test volume: density of drifting, pulsing soft blobs at animation time `time`, layers z0.. of the slice.
layout(local_size_x = 8, local_size_y = 4, local_size_z = 4) in;
layout(binding = 0, r16f) uniform writeonly image3D density;
uniform float time;
uniform int z0;

float blob(vec3 p, vec3 c, float r) {
    vec3 d = (p - c) / r;
    return exp(-2.5 * dot(d, d));
}

void main() {
    ivec3 size = imageSize(density);
    ivec3 cell = ivec3(gl_GlobalInvocationID.xy, int(gl_GlobalInvocationID.z) + z0);
    if (any(greaterThanEqual(cell, size))) return;
    vec3 p = (vec3(cell) + 0.5) / vec3(size);          // [0,1]^3, y is height
    float d = 0.0;
    for (int i = 0; i < 7; ++i) {
        float fi = float(i);
        float a = time * (0.15 + 0.04 * fi) + fi * 2.1;
        vec3 c = vec3(0.5 + 0.3 * cos(a), 0.35 + 0.12 * sin(1.7 * a + fi), 0.5 + 0.3 * sin(a * 1.3));
        float r = 0.16 + 0.05 * sin(time * 0.7 + fi);
        d = max(d, blob(p, c, r));
    }
    float ripple = 0.5 + 0.5 * sin(23.0 * p.x + 2.0 * time) * sin(19.0 * p.z - 1.3 * time) * sin(31.0 * p.y);
    d *= mix(0.7, 1.0, ripple) * smoothstep(0.0, 0.15, p.y) * smoothstep(1.0, 0.75, p.y);
    imageStore(density, cell, vec4(d));
}
