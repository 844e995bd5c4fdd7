#version 430
// Terrain: grass on flat ground, rock on slopes, lighter tops; Lambert sun light plus the Sun's sky ambient
// (weighted toward upward normals, as the meshes are: plugins/mesh/reference.py).
// Alpha 1: opaque, hides the sky (color.a is the sky occlusion, atmos/render_core.py).
// sun_dir, sun_color, sky_ambient: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
in vec3 v_world;
in vec3 v_normal;
out vec4 frag;
uniform float relief;

void main() {
    vec3 n = normalize(v_normal);
    vec3 s = normalize(sun_dir);
    float slope = 1.0 - n.y;
    vec3 grass = vec3(0.16, 0.30, 0.09);
    vec3 rock = vec3(0.36, 0.32, 0.28);
    vec3 base = mix(grass, rock, smoothstep(0.12, 0.35, slope));
    base = mix(base, vec3(0.55, 0.55, 0.5), smoothstep(0.75, 1.0, v_world.y / max(relief, 1e-3)));
    vec3 light = sun_color * max(dot(n, s), 0.0) + sky_ambient * (0.6 + 0.4 * n.y);
    frag = vec4(base * light, 1.0);
}
