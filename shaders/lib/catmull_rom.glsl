// Catmull-Rom weights of the taps at -1, 0, 1, 2 for a fraction t in [0, 1) (Horner form); float64 twin:
// atmos.glsl_math.catmull_rom_weights. Used by the TAA's history read and the shear-warp's warp.
#ifndef CATMULL_ROM_GLSL_INCLUDED
#define CATMULL_ROM_GLSL_INCLUDED
vec4 catmull_rom_weights(float t) {
    return vec4(t * (-0.5 + t * (1.0 - 0.5 * t)), 1.0 + t * t * (-2.5 + 1.5 * t),
                t * (0.5 + t * (2.0 - 1.5 * t)), t * t * (-0.5 + 0.5 * t));
}
#endif
