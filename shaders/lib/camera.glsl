// The physical camera's state for this frame (plugins/physical_camera; the buffer "camera_exposure"):
// written on the GPU by its adapt pass, read by the present. Float offsets are what
// plugins/physical_camera/plugin.py reads back (STATE_FIELDS); change both together.
#ifndef CAMERA_GLSL_INCLUDED
#define CAMERA_GLSL_INCLUDED
layout(std430, binding = 1) buffer Camera {
    float exposure;    // linear scale of the HDR colour: 1 / (1.2 * 2^ev100)
    float bloom;       // the bloom's weight in the present's mix
    float ev100;       // the adapted EV100
    float target;      // the EV100 it adapts toward (metered, compensated, clamped)
    float primed;      // 1 once a frame was metered (the next adapts from it)
};
#endif
