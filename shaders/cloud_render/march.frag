#version 430
// Reference image of the cloud layer: MARCH_STEPS midpoint samples per view ray through the
// layer's box, density and light trilinear from mix(A, B, t), extinction sigma_t (1/m at density 1)
// along the world path, stopped at scene depth; the source J of volume.glsl per sample.
// Premultiplied: rgb = light, a = 1 - transmittance.
#include "cloud_render/volume.glsl"
#include "lib/view_ray.glsl"
in vec2 v_uv;
out vec4 frag;
layout(binding = 5) uniform sampler2D scene_depth;
uniform mat3 view_basis;       // atmos.camera.set_camera_uniforms (lib/view_ray.glsl)
uniform vec3 camera_pos;
uniform float near;
uniform float far;
uniform vec3 layer_min;
uniform vec3 layer_max;
uniform vec3 cell_size;
uniform float sigma_t;

void main() {
    vec3 dir = view_ray_dir(v_uv, view_basis);
    float scene = view_ray_distance(v_uv, texture(scene_depth, v_uv).r, view_basis, near, far, 1e30);
    vec3 safe = mix(dir, vec3(1e-12), lessThan(abs(dir), vec3(1e-12)));
    vec3 t0 = (layer_min - camera_pos) / safe, t1 = (layer_max - camera_pos) / safe;
    float enter = max(max(max(min(t0.x, t1.x), min(t0.y, t1.y)), min(t0.z, t1.z)), 0.0);
    float leave = min(min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z)), scene);
    vec3 light = vec3(0.0);
    float trans = 1.0;
    if (leave > enter) {
        float dt = (leave - enter) / float(MARCH_STEPS);
        vec3 extent = layer_max - layer_min;
        float ny = extent.y / cell_size.y;
        for (int i = 0; i < MARCH_STEPS && trans > 1e-4; ++i) {
            vec3 uvw = (camera_pos + dir * (enter + (float(i) + 0.5) * dt) - layer_min) / extent;
            float d = cloud_density(uvw);
            if (d <= 0.0) continue;
            float a = 1.0 - exp(-sigma_t * d * dt);
            light += trans * a * cloud_source(uvw, dir, ny);
            trans *= 1.0 - a;
        }
    }
    frag = vec4(light, 1.0 - trans);
}
