#version 430
// Volumetric FBM fog over the scene, stopped at scene depth; blend ONE, SRC_ALPHA. LOCAL_MEDIA 1: the
// same onto the media targets (lib/media_out.glsl).
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
#include "lib/view_ray.glsl"
#include "volumetric_fog/medium.glsl"
in vec2 v_uv;
out vec4 frag;
#include "lib/media_out.glsl"
layout(binding = 0) uniform sampler2D scene_depth;
uniform mat3 view_basis;       // atmos.camera.set_camera_uniforms (lib/view_ray.glsl)
uniform vec3 camera_pos;
uniform float near;
uniform float far;

void main() {
    vec3 dir = view_ray_dir(v_uv, view_basis);
    float dist = view_ray_distance(v_uv, texture(scene_depth, v_uv).r, view_basis, near, far, 1e30);
    frag = fog_march(camera_pos, dir, dist);
    write_media(frag);
}
