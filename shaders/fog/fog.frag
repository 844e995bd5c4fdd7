#version 430
// Fog post-process: f from fog/factor.glsl, output premultiplied for blend (ONE, SRC_ALPHA):
// rgb = (1 - f) * fog_color, a = f, so the target becomes f * C_current + (1 - f) * C_fog, eq. (1).
// FOG_FROM_DEPTH 1: distance and position from the scene depth and the inverse view-projection;
// 0 (apply_fog): from a distance texture (+inf = sky) and a world-position texture.
in vec2 v_uv;
out vec4 frag;
#include "fog/factor.glsl"
uniform vec3 fog_color;
uniform int fog_sky_keep;    // 1: sky pixels are left to the sky
#if FOG_FROM_DEPTH
layout(binding = 0) uniform sampler2D scene_depth;
uniform mat4 inv_view_proj;
uniform vec3 camera_pos;
#else
layout(binding = 0) uniform sampler2D fog_distance;
layout(binding = 1) uniform sampler2D fog_position;
uniform float fog_far;       // distance sky pixels are fogged at (may be +inf)
#endif

void main() {
#if FOG_FROM_DEPTH
    float z = texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r;   // exact texel: no blend across edges
    bool sky = z >= 1.0;
    vec4 h = inv_view_proj * vec4(v_uv * 2.0 - 1.0, min(z, 1.0) * 2.0 - 1.0, 1.0);
    vec3 world = h.xyz / h.w;                 // sky: the far-plane point of this pixel
    float d = length(world - camera_pos);
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
