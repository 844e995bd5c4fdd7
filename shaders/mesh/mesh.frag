#version 430
// Instanced meshes lit by the sun (Lambert) and the sky's ambient light, weighted toward normals that
// face up; numpy reference: atmos.plugins.mesh.reference.mesh_color. Alpha 1: opaque (the sky
// occlusion, atmos/render_core.py). Cloud shadows and fog come after, from the depth written here.
// sun_dir, sun_color, sky_ambient: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
in vec3 v_normal;
in vec3 v_color;
out vec4 frag;

void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;                   // open meshes are lit from both sides
    vec3 light = sun_color * max(dot(n, normalize(sun_dir)), 0.0) + sky_ambient * (0.6 + 0.4 * n.y);
    frag = vec4(v_color * light, 1.0);
}
