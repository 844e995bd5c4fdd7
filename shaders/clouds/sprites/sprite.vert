#version 430
// One cloud particle per instance's block (sprite.glsl): each instance is one segment, gl_VertexID a
// block's place in its unit's drawing order (blending is in vertex order, so of two neighbouring
// sprites the farther is drawn first); culled sprites are thrown out of the view volume.
#define CLOUD_EXACT_FILTER
#include "lib/frame.glsl"
#include "clouds/volume/volume.glsl"
#include "clouds/sprites/sprite.glsl"
layout(location = 0) in ivec4 in_segment;
flat out vec4 v_octaves;
flat out vec3 v_slope;
flat out vec3 v_ambient;
flat out vec4 v_field;
flat out vec3 v_sun;
flat out vec3 v_center;
flat out float v_radius;
flat out float v_tau;
flat out vec3 v_conic;
flat out float v_falloff;
flat out float v_coverage;
flat out float v_stretch;

void main() {
    Sprite o;
    sprite_setup(in_segment, gl_VertexID, o);
    gl_Position = o.position;
    gl_PointSize = o.point_size;
    v_octaves = o.octaves;
    v_slope = o.slope;
    v_ambient = o.ambient;
    v_field = o.field;
    v_sun = o.sun;
    v_center = o.center;
    v_radius = o.radius;
    v_tau = o.tau;
    v_conic = o.conic;
    v_falloff = o.falloff;
    v_coverage = o.coverage;
    v_stretch = o.stretch;
}
