#version 430
// sky/sky.glsl for a list of directions (tests, and anyone who needs sky colours on the GPU).
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Directions { vec4 directions[]; };
layout(std430, binding = 1) writeonly buffer Colors { vec4 colors[]; };
uniform uint count;
#include "sky/sky.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    colors[i] = vec4(sky_color(normalize(directions[i].xyz)), 1.0);
}
