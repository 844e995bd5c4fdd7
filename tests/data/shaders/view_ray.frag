#version 430
// Test shader (tests/test_view_ray.py): lib/view_ray.glsl per pixel, (unit direction, distance or `none`).
#include "lib/view_ray.glsl"
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D scene_depth;     // r32f: window-space depth per pixel
uniform mat3 view_basis;
uniform float near;
uniform float far;
uniform float none;

void main() {
    float depth = texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r;
    frag = vec4(view_ray_dir(v_uv, view_basis), view_ray_distance(v_uv, depth, view_basis, near, far, none));
}
