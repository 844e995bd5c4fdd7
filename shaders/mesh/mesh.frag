#version 430
// Instanced meshes lit by the sun (Lambert) and the sky's ambient light, weighted toward normals that
// face up; numpy reference: atmos.plugins.mesh.reference.mesh_color. Alpha 1: opaque (the sky
// occlusion, atmos/render_core.py). Cloud shadows and fog come after, from the depth written here.
// `motion` (location 1, drawn only while the motion target is bound: atmos.render_core.MotionTargets):
// the surface's world motion since the last frame, tagged with the depth this fragment writes.
// sun_dir, sun_color, sky_ambient: the frame block (lib/frame.glsl)
#include "lib/frame.glsl"
in vec3 v_normal;
in vec3 v_color;
in vec3 v_motion;
layout(location = 0) out vec4 frag;
layout(location = 1) out vec4 motion;

void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;                   // open meshes are lit from both sides
    vec3 light = sun_color * max(dot(n, normalize(sun_dir)), 0.0) + sky_ambient * (0.6 + 0.4 * n.y);
    frag = vec4(v_color * light, 1.0);
    motion = vec4(v_motion, gl_FragCoord.z);
}
