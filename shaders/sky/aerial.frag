#version 430
// Aerial perspective of the physical sky (SkySettings.aerial_perspective): the air between the camera
// and what each pixel shows scatters sunlight toward the camera and dims what lies behind it, marched
// per pixel through the same atmosphere and LUTs as the sky (sky/atmosphere.glsl atm_aerial, AERIAL_STEPS
// segments). Output premultiplied for blend (ONE, SRC_ALPHA): rgb = in-scattered light, a = the mean
// of the RGB transmittance (Hillaire's grey transmittance), so the target becomes L + T·C. Sky pixels
// (depth 1) already hold the whole ray: left alone. AERIAL_CLOUDS 1: "cloud_distance" (premultiplied
// (a·d, a), atmos/composition.py) gives the clouds their own distance: a·AP(d_cloud) + (1 - a)·AP(d).
// float64 reference: plugins/sky/atmosphere.py aerial_perspective.
in vec2 v_uv;
out vec4 frag;
layout(binding = 0) uniform sampler2D scene_depth;
#if AERIAL_CLOUDS
#include "lib/cloud_distance.glsl"
layout(binding = 2) uniform sampler2D cloud_distance;
#endif
uniform mat3 view_basis;       // atmos.camera.set_camera_uniforms (lib/view_ray.glsl)
uniform float near;
uniform float far;
uniform float view_r;          // the camera's radius from the planet's centre
uniform vec3 sun_dir;          // unit, toward the sun
#include "lib/view_ray.glsl"
#include "sky/atmosphere.glsl"

vec4 aerial(vec3 dir, float distance) {
    vec3 transmittance;
    vec3 light = atm_aerial(view_r, dir.y, sun_dir.y, dot(dir, sun_dir), distance, AERIAL_STEPS, transmittance);
    return vec4(light, dot(transmittance, vec3(1.0 / 3.0)));
}

void main() {
    float z = texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r;
    vec3 ray = view_ray(v_uv, view_basis);
    vec3 dir = normalize(ray);
    vec4 ap = z >= 1.0 ? vec4(0.0, 0.0, 0.0, 1.0) : aerial(dir, view_depth(z, near, far) * length(ray));
#if AERIAL_CLOUDS
    vec2 cloud = cloud_cover_distance(texelFetch(cloud_distance, ivec2(gl_FragCoord.xy), 0).rg);
    if (cloud.x > 0.0) ap = cloud.x * aerial(dir, cloud.y) + (1.0 - cloud.x) * ap;
#endif
    frag = ap;
}
