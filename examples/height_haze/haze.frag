#version 430
// Exponential height haze: density(y) = density * exp(-(y - base) / scale_height) between the camera
// and the surface (or max_distance for the sky). Output premultiplied for blend (ONE, SRC_ALPHA):
// rgb = (1 - T) * haze_color, a = T, so the colour becomes T * C + (1 - T) * haze_color.
#include "lib/view_ray.glsl"
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D scene_depth;
uniform mat3 view_basis;      // atmos.set_camera_uniforms
uniform vec3 camera_pos;
uniform float near;
uniform float far;
uniform float density;        // extinction (1/m) at height base
uniform float base;
uniform float scale_height;
uniform float max_distance;   // how far the sky is hazed
uniform vec3 haze_color;

void main() {
    float depth = texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r;
    float s = view_ray_distance(v_uv, depth, view_basis, near, far, max_distance);
    vec3 dir = view_ray_dir(v_uv, view_basis);
    // optical depth: integral of density(y0 + t dy) over t in [0, s]
    float k = dir.y * s / scale_height;
    float along = abs(k) < 1e-4 ? s * (1.0 - 0.5 * k) : scale_height * (1.0 - exp(-k)) / dir.y;
    float tau = density * exp(-(camera_pos.y - base) / scale_height) * along;
    float t = exp(-tau);
    frag = vec4((1.0 - t) * haze_color, t);
}
