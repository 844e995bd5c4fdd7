#version 430
// Fog post-process: f from fog/factor.glsl, output premultiplied for blend (ONE, SRC_ALPHA):
// rgb = (1 - f) * fog_color, a = f, so the target becomes f * C_current + (1 - f) * C_fog, eq. (1).
// FOG_FROM_DEPTH 1: distance and position from the scene depth and the camera (lib/view_ray.glsl);
// 0 (apply_fog): from a distance texture (+inf = sky) and a world-position texture.
in vec2 v_uv;
out vec4 frag;
#include "fog/factor.glsl"
uniform vec3 fog_color;
uniform int fog_sky_keep;    // 1: sky pixels are left to the sky
#if FOG_FROM_DEPTH
#include "lib/view_ray.glsl"
layout(binding = 0) uniform sampler2D scene_depth;
uniform mat3 view_basis;     // atmos.camera.set_camera_uniforms (lib/view_ray.glsl)
uniform vec3 camera_pos;
uniform float near;
uniform float far;
#else
layout(binding = 0) uniform sampler2D fog_distance;
layout(binding = 1) uniform sampler2D fog_position;
uniform float fog_far;       // distance sky pixels are fogged at (may be +inf)
#endif

void main() {
#if FOG_FROM_DEPTH
    float z = texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r;   // exact texel: no blend across edges
    bool sky = z >= 1.0;
    vec3 ray = view_ray(v_uv, view_basis);
    float view_z = sky ? far : view_depth(z, near, far);
    vec3 world = camera_pos + ray * view_z;   // sky: the far-plane point of this pixel
    float d = view_z * length(ray);
#else
    ivec2 px = ivec2(gl_FragCoord.xy);
    float d = texelFetch(fog_distance, px, 0).r;
    vec3 world = texelFetch(fog_position, px, 0).xyz;
    bool sky = d > 3.0e38;
    if (sky) d = fog_far;
#endif
    if (sky && fog_sky_keep != 0) {
        frag = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    float f = fog_factor(d, world);
    frag = vec4(fog_color * (1.0 - f), f);
}
