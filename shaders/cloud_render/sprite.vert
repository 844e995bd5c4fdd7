#version 430
// One cloud particle per cell of a sprite group (thesis 6.2): the static vertex buffer holds the
// group's local (x, z) cells, each instance one segment (group x, slice y, group z). Empty cells
// and cells past the volume's edge are thrown out of the view volume.
#include "cloud_render/volume.glsl"
layout(location = 0) in ivec2 in_cell;
layout(location = 1) in ivec3 in_segment;
uniform ivec3 volume_shape;
uniform ivec2 group_size;
uniform vec3 layer_min;        // world corner of cell (0, 0, 0)
uniform vec3 cell_size;
uniform mat4 view_proj;
uniform float base_diameter;   // world sprite diameter at density 1: size factor × max(cx, cz)
uniform float pixel_scale;     // pixel diameter = world diameter × pixel_scale / clip.w
uniform float max_point_size;
uniform float tau_scale;       // optical depth at the sprite centre = tau_scale × density / diameter²
flat out vec3 v_light;
flat out float v_tau;
flat out float v_coverage;     // < 1 for sprites smaller than a pixel: their area in pixels

const vec4 CULLED = vec4(0.0, 0.0, 2.0, 1.0);   // z > w: outside the clip volume

void main() {
    ivec3 cell = ivec3(in_segment.x * group_size.x + in_cell.x, in_segment.y,
                       in_segment.z * group_size.y + in_cell.y);
    v_light = vec3(0.0);
    v_tau = 0.0;
    v_coverage = 0.0;
    gl_PointSize = 1.0;
    gl_Position = CULLED;
    if (any(greaterThanEqual(cell, volume_shape))) return;
    float d = mix(texelFetch(density_a, cell, 0).r, texelFetch(density_b, cell, 0).r, t);
    if (!(d > 0.0)) return;
    vec3 uvw = (vec3(cell) + 0.5) / vec3(volume_shape);
    vec4 clip = view_proj * vec4(layer_min + (vec3(cell) + 0.5) * cell_size, 1.0);
    float diameter = base_diameter * (0.5 + 0.5 * min(d, 1.0));
    float px = diameter * pixel_scale / max(clip.w, 1e-6);
    float c = clamp(px, 0.0, 1.0);
    v_coverage = c * c;
    gl_PointSize = clamp(px, 1.0, max_point_size);
    v_tau = tau_scale * d / (diameter * diameter);
    v_light = cloud_light(uvw);
    gl_Position = clip;
}
