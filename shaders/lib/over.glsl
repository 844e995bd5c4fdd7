// Premultiplied "over", what the raster blend (ONE, ONE_MINUS_SRC_ALPHA) did, for compute passes that
// composite a layer in place: its (light, a) in front of the colour below, and its distance pair
// (a·d, a) in front of the one below (atmos/composition.py).
#ifndef OVER_INCLUDED
#define OVER_INCLUDED
vec4 over(vec4 layer, vec4 below) { return layer + (1.0 - layer.a) * below; }
vec2 over(vec2 layer, vec2 below) { return layer + (1.0 - layer.y) * below; }
#endif
