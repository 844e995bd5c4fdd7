#version 430
// The fog drawn over a fullscreen triangle (fog/medium.glsl), blended (ONE, SRC_ALPHA): what apply_fog
// draws from distance and position textures (FOG_FROM_DEPTH 0); the graph's pass is fog/fog.comp.
in vec2 v_uv;
out vec4 frag;
#include "lib/media_out.glsl"
#include "fog/medium.glsl"

void main() {
    frag = fog_medium(ivec2(gl_FragCoord.xy), v_uv);
    write_media(frag);
}
