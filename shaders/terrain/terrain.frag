#version 430
// Terrain: the albedo of terrain/material.glsl (grass, rock on slopes, snow high up, detail fading with
// the pixel's footprint) under Lambert sun light plus the Sun's sky ambient (weighted toward upward
// normals, as the meshes are: plugins/mesh/reference.py).
// Alpha 1: opaque, hides the sky (color.a is the sky occlusion, atmos/render_core.py).
// sun_dir, sun_color, sky_ambient, camera_pos, view_basis, resolution: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
#include "lib/hash.glsl"
#include "lib/value_noise.glsl"
#include "terrain/material.glsl"
in vec3 v_world;
in vec3 v_normal;
out vec4 frag;
uniform float relief;
uniform float snowline;
uniform float rock_slope;

void main() {
    vec3 n = normalize(v_normal);
    vec3 s = normalize(sun_dir);
    // The pixel's footprint on the ground (m): its angle times the distance, stretched at grazing angles.
    vec3 to_eye = camera_pos - v_world;
    float d = length(to_eye);
    float pixel = 2.0 * length(view_basis[1]) / resolution.y;
    float footprint = pixel * d / max(abs(dot(n, to_eye)) / max(d, 1e-6), 0.25);
    vec3 base = terrain_albedo(v_world, n, footprint, relief, snowline, rock_slope);
    vec3 light = sun_color * max(dot(n, s), 0.0) + sky_ambient * (0.6 + 0.4 * n.y);
    frag = vec4(base * light, 1.0);
}
