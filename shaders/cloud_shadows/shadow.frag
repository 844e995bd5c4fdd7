#version 430
// Cloud ground shadows (thesis 7.3.1): the scene point behind each pixel is projected along the
// direction toward the sun onto the middle of the cloud layer, where the top-view summed density
// mix(A, B, t) (layer 0 of the density maps, each set at its own placement) gives the optical depth. Output is the factor the
// colour is multiplied by (blend ZERO, SRC_COLOR); plugins/cloud_shadows/reference.py is the same in numpy.
#include "lib/view_ray.glsl"
out vec4 frag;
layout(binding = 0) uniform sampler2DArray sums_a;
layout(binding = 1) uniform sampler2DArray sums_b;
layout(binding = 2) uniform sampler2D scene_depth;
uniform mat3 view_basis;       // atmos.camera.set_camera_uniforms (lib/view_ray.glsl)
uniform vec3 camera_pos;
uniform float near;
uniform float far;
uniform vec3 sun_dir;          // unit, toward the sun
uniform float weight;          // direct_fraction × horizon fade (reference.direct_weight)
uniform float extinction;      // sigma × strength, per cell of summed density
uniform float t;               // interpolation factor between A and B
uniform ivec2 a_shift;         // (x, z) cells from B's column to A's at the same place (CloudSets.a_shift)
uniform vec3 layer_min;        // world corner of cell (0, 0, 0): (origin.x·cx, base_altitude, origin.z·cz)
uniform vec3 cell_size;
uniform ivec3 shape;

const float MIN_SUN_HEIGHT = 1e-4;

bool outside(ivec2 c) {
    return any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c, shape.xz));
}

// Column c of B's placement (layer_min), A read at its own (c + a_shift): zero outside either volume.
float column(ivec2 c) {
    if (outside(c)) return 0.0;
    ivec2 ca = c + a_shift;
    float a = outside(ca) ? 0.0 : texelFetch(sums_a, ivec3(ca, 0), 0).r;
    return mix(a, texelFetch(sums_b, ivec3(c, 0), 0).r, t);
}

// Bilinear, texel i centred at i, zero outside the volume.
float column_sum(vec2 p) {
    if (any(lessThanEqual(p, vec2(-1.0))) || any(greaterThanEqual(p, vec2(shape.xz)))) return 0.0;
    vec2 i0 = floor(p);
    vec2 f = p - i0;
    ivec2 i = ivec2(i0);
    return mix(mix(column(i), column(i + ivec2(1, 0)), f.x),
               mix(column(i + ivec2(0, 1)), column(i + ivec2(1, 1)), f.x), f.y);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = texelFetch(scene_depth, pixel, 0).r;
    if (depth >= 1.0 || weight <= 0.0) {
        frag = vec4(1.0);
        return;
    }
    vec2 uv = gl_FragCoord.xy / vec2(textureSize(scene_depth, 0));
    vec3 p = camera_pos + view_ray(uv, view_basis) * view_depth(depth, near, far);
    float thickness = float(shape.y) * cell_size.y;
    float run = max(layer_min.y + 0.5 * thickness - p.y, 0.0) / max(sun_dir.y, MIN_SUN_HEIGHT);
    vec3 q = p + run * sun_dir;
    vec2 texel = (q.xz - layer_min.xz) / cell_size.xz - 0.5;
    float above = clamp((layer_min.y + thickness - p.y) / thickness, 0.0, 1.0);
    float tau = extinction * column_sum(texel) * above;
    frag = vec4(vec3(1.0 - weight * (1.0 - exp(-tau))), 1.0);
}
