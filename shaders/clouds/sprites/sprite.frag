#version 430
// A soft cloud particle: opacity 1 - exp(-tau × profile), the profile (exp(-Q/2) - exp(-k)) / (1 - exp(-k)),
// Q = p^T conic p (the block's mass footprint, sprite.vert; particle.py), premultiplied (blend ONE, ONE_MINUS_SRC_ALPHA);
// its light J (volume.glsl) with the phase function at this pixel's view ray through the sprite's plane.
// Soft particle: × clamp(1/2 + (scene view depth - sprite view depth) / (2 radius), 0, 1), the share of
// its depth span [centre - radius, centre + radius] in front of the surface, so a sprite meeting terrain
// fades out across it instead of cutting a line (float64: reference.soft_fade; sprite.vert depth-tests
// the sprite at its front). The scene
// depth is the attached depth target's (depth writes are off): "depth", or off screen the block's farthest.
#include "lib/frame.glsl"
#include "clouds/volume/volume.glsl"
#include "lib/view_ray.glsl"
layout(binding = 5) uniform sampler2D scene_depth;
// near, far, camera_pos: the frame block (lib/frame.glsl)
uniform vec3 camera_right;
uniform vec3 camera_up;
flat in vec4 v_octaves;
flat in vec3 v_slope;          // log T's slope across the sprite (sprite.vert)
flat in vec3 v_ambient;
flat in vec4 v_field;          // the diffusion field at the sprite's centre (volume.glsl cloud_diffusion)
flat in vec3 v_sun;            // the sun's source at its height (volume.glsl sun_source_at)
flat in vec3 v_center;
flat in float v_radius;
flat in float v_tau;
flat in vec3 v_conic;
flat in float v_falloff;
flat in float v_coverage;
flat in float v_stretch;
out vec4 frag;
layout(location = 1) out vec4 frag_distance;   // (a·distance, a): "cloud_distance" when attached (atmos/composition.py)

void main() {
    float scene = view_depth(texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r, near, far);
    float soft = clamp(0.5 + 0.5 * (scene - 1.0 / gl_FragCoord.w) / v_radius, 0.0, 1.0);   // 1 / w: its view depth
    vec2 pc = (gl_PointCoord - 0.5) * vec2(2.0, -2.0);
    float e = exp(-v_falloff), form = dot(pc * pc, v_conic.xz) + 2.0 * v_conic.y * pc.x * pc.y;
    float profile = max(exp(-0.5 * form) - e, 0.0) / (1.0 - e);
    float a = (1.0 - exp(-v_tau * profile)) * v_coverage * soft;
    vec2 q = pc * (v_radius * v_stretch);          // the point's side spans stretch × diameter (sprite.vert)
    vec3 ray = normalize(v_center + q.x * camera_right + q.y * camera_up - camera_pos);
    vec4 ai = octave_exponents();                                        // octave i: exp(e_i (h.pc - e_i var))
    vec4 across = exp(clamp(ai * (dot(v_slope.xy, pc) - ai * v_slope.z), -40.0, 40.0));
    vec3 J = sun_part(v_octaves * across, dot(ray, light_dir), v_sun) + diffusion_light(v_field, ray, v_sun) + v_ambient;
    frag = vec4(min(J, vec3(HDR_MAX)) * a, a);   // volume.glsl: the blends never reach inf in float16
    frag_distance = vec4(a * length(v_center - camera_pos), a, 0.0, a);   // blends by its own alpha
}
