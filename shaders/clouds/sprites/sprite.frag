#version 430
// A soft cloud particle (sprite.glsl sprite_shade), premultiplied (blend ONE, ONE_MINUS_SRC_ALPHA).
// sprite.vert depth-tests the sprite at its front; the soft fade reads the attached depth target
// (depth writes are off): "depth", or off screen the block's farthest.
#include "lib/frame.glsl"
#include "clouds/volume/volume.glsl"
#include "lib/view_ray.glsl"
#include "clouds/sprites/sprite.glsl"
layout(binding = 5) uniform sampler2D scene_depth;
flat in vec4 v_octaves;
flat in vec3 v_slope;
flat in vec3 v_ambient;
flat in vec4 v_field;
flat in vec3 v_sun;
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
    Sprite o = Sprite(gl_FragCoord / gl_FragCoord.w, 1.0, v_octaves, v_slope, v_ambient, v_field, v_sun, v_center,
                      v_radius, v_tau, v_conic, v_falloff, v_coverage, v_stretch);
    float scene = view_depth(texelFetch(scene_depth, ivec2(gl_FragCoord.xy), 0).r, near, far);
    vec2 pc = (gl_PointCoord - 0.5) * vec2(2.0, -2.0);
    frag = sprite_shade(o, pc, scene, 1.0 / gl_FragCoord.w);   // 1 / w: its view depth
    frag_distance = vec4(frag.a * length(v_center - camera_pos), frag.a, 0.0, frag.a);   // blends by its own alpha
}
