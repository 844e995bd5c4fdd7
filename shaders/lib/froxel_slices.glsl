// Froxel slices along a view ray: slice coordinate w in [0, 1] <-> distance d, logarithmic beyond `knee`
// and nearly linear inside it, w = ln(1 + d / knee) / ln(1 + range / knee): even steps of the distance's
// ratio far out, no slice wasted near the camera. The sky's aerial perspective (sky/aerial_slices.glsl)
// and the volumetric fog's froxels (volumetric_fog/froxels.comp) use it.
float froxel_w(float d, float range, float knee) {
    return log(1.0 + max(d, 0.0) / knee) / log(1.0 + range / knee);
}

float froxel_distance(float w, float range, float knee) {
    return knee * (exp(w * log(1.0 + range / knee)) - 1.0);
}
