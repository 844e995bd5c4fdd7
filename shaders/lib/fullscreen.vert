#version 430
// A triangle that covers the viewport, drawn with no vertex buffer: render(vertices=3).
#include "lib/fullscreen_body.glsl"
