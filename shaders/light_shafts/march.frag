#version 430
// Light shafts marched through the cloud shadow map, at low resolution: along the view ray of each
// low-res texel (the centre of its block) to the block's farthest scene depth (the sky: max_distance),
// `steps` samples from a jittered start gather the sun light a thin haze scatters toward the eye,
//   L = sum_i scattering * phase(cos) * E * exp(-tau_sun(p_i)) * exp(-scattering * s_i) * ds,
// tau_sun through the clouds from the density maps (cloud_shadows/column.glsl; has_clouds 0: none;
// with CLOUD_FAR_FIELD also the far field's columns beyond the volume: rays between far clouds).
// Output (L, T = exp(-scattering * d)), upsampled by cloud_render/composite.frag and blended
// rgb = L + T * rgb. plugins/light_shafts/reference.py march_shafts is the same in numpy.
#include "lib/view_ray.glsl"
#include "lib/hash.glsl"
#include "lib/phase.glsl"
#include "cloud_shadows/column.glsl"
layout(binding = 2) uniform sampler2D low_depth;   // the farthest scene depth of each block
uniform mat3 view_basis;       // atmos.camera.set_camera_uniforms (lib/view_ray.glsl)
uniform vec3 camera_pos;
uniform float near;
uniform float far;
uniform vec3 sun_dir;          // unit, toward the sun
uniform vec3 irradiance;       // sun_intensity * Sun.color * horizon fade
uniform vec3 lobes;            // phase_g, phase_g2, phase_w
uniform float scattering;      // 1/m
uniform float max_distance;
uniform int steps;
uniform int has_clouds;
uniform int factor;
uniform vec2 frame_size;
out vec4 frag;

// Per-texel start offset in [0, 1): lowbias32 of x + 65536 y (atmos.hashing.lowbias32), 24 bits.
float jitter(ivec2 q) {
    return float(atmos_lowbias32(uint(q.x) + 65536u * uint(q.y)) >> 8) / 16777216.0;
}

void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    vec2 uv = (vec2(q) + 0.5) * float(factor) / frame_size;
    vec3 ray = view_ray(uv, view_basis);
    vec3 dir = normalize(ray);
    float d = min(view_ray_distance(uv, texelFetch(low_depth, q, 0).r, view_basis, near, far, max_distance),
                  max_distance);
    float ds = d / float(steps);
    float j = jitter(q);
    float sum = 0.0;
    for (int i = 0; i < steps; ++i) {
        float s = (float(i) + j) * ds;
        float tau = has_clouds != 0 ? sun_optical_depth(camera_pos + dir * s, sun_dir) : 0.0;
        sum += exp(-tau - scattering * s);
    }
    vec3 light = irradiance * (scattering * phase2(dot(dir, sun_dir), lobes) * sum * ds);
    frag = vec4(light, exp(-scattering * d));
}
