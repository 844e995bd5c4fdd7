// The aerial perspective's froxel slices (sky/aerial_volume.comp writes them, sky/aerial.comp reads
// them): lib/froxel_slices.glsl with a knee of AERIAL_KNEE — even steps of the distance's ratio far out,
// where the air's colour and extinction change with the altitudes the ray crosses, and no slice wasted
// near the camera, where they are constant.
#include "lib/froxel_slices.glsl"
const float AERIAL_KNEE = 1000.0;      // m

float aerial_slice_w(float d, float range) {
    return froxel_w(d, range, AERIAL_KNEE);
}

float aerial_slice_distance(float w, float range) {
    return froxel_distance(w, range, AERIAL_KNEE);
}
