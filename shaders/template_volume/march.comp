#version 430
// Template volume ray march, one compute invocation per pixel: density = mix(A, B, t); Beer-Lambert
// extinction, a short light march toward the sun, stopped at scene depth. The premultiplied result,
// rgb = in-scattered light, a = coverage 1 - transmittance, is composited over the colour in place
// (lib/over.glsl: light + transmittance * scene, the coverage added to color.a, the sky occlusion of
// atmos/render_core.py: the volume is a cloud).
// view_basis, camera_pos, near, far, sun_dir, sun_color: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
#include "lib/over.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) uniform image2D color_image;
layout(binding = 0) uniform sampler3D density_a;
layout(binding = 1) uniform sampler3D density_b;
layout(binding = 2) uniform sampler2D scene_depth;
uniform vec3 box_min;
uniform vec3 box_max;
uniform float t;

#include "lib/view_ray.glsl"

const float SIGMA = 1.2;   // extinction per metre at density 1

float density(vec3 world) {
    vec3 uvw = (world - box_min) / (box_max - box_min);
    if (any(lessThan(uvw, vec3(0.0))) || any(greaterThan(uvw, vec3(1.0)))) return 0.0;
    return mix(texture(density_a, uvw).r, texture(density_b, uvw).r, t);
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(color_image);
    if (any(greaterThanEqual(px, size))) return;
    vec2 v_uv = (vec2(px) + 0.5) / vec2(size);
    vec3 dir = view_ray_dir(v_uv, view_basis);
    float z = texelFetch(scene_depth, px, 0).r;
    float scene_dist = view_ray_distance(v_uv, z, view_basis, near, far, 1e30);

    vec3 inv = 1.0 / dir;
    vec3 t0 = (box_min - camera_pos) * inv, t1 = (box_max - camera_pos) * inv;
    float enter = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    float leave = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), scene_dist));
    vec3 light = vec3(0.0);
    float trans = 1.0;
    if (leave > enter) {
        float dt = (leave - enter) / float(MARCH_STEPS);
        vec3 s = normalize(sun_dir);
        float day = smoothstep(-0.1, 0.1, s.y);
        vec3 ambient = vec3(0.35, 0.42, 0.55) * mix(0.1, 1.0, day);
        for (int i = 0; i < MARCH_STEPS && trans > 0.01; ++i) {
            vec3 p = camera_pos + dir * (enter + (float(i) + 0.5) * dt);
            float d = density(p);
            if (d < 1e-3) continue;
            float od = 0.0;
            for (int j = 1; j <= 4; ++j) od += density(p + s * float(j) * 1.5) * 1.5;
            float step_t = exp(-SIGMA * d * dt);
            vec3 lit = sun_color * day * exp(-SIGMA * od) + ambient;
            light += trans * (1.0 - step_t) * lit;
            trans *= step_t;
        }
    }
    if (trans < 1.0) imageStore(color_image, px, over(vec4(light, 1.0 - trans), imageLoad(color_image, px)));
}
