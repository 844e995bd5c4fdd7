#version 430
// The fullscreen triangle on the far plane (window depth 1): with the depth test "<=" and depth
// writes off it draws only where nothing was drawn (atmos.render_core.where_nothing_was_drawn).
#define FULLSCREEN_Z 1.0
#include "lib/fullscreen_body.glsl"
