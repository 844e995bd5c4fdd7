// The aerial perspective's froxel slices (sky/aerial_volume.comp writes them, sky/aerial.frag reads
// them): slice coordinate w in [0, 1] <-> distance d along the ray, logarithmic beyond AERIAL_KNEE and
// nearly linear inside it, w = ln(1 + d / knee) / ln(1 + range / knee) (slice z's centre at w = (z + 0.5)
// / D): even steps of the distance's ratio far out, where the air's colour and extinction change with
// the altitudes the ray crosses, and no slice wasted near the camera, where they are constant.
const float AERIAL_KNEE = 1000.0;      // m

float aerial_slice_w(float d, float range) {
    return log(1.0 + max(d, 0.0) / AERIAL_KNEE) / log(1.0 + range / AERIAL_KNEE);
}

float aerial_slice_distance(float w, float range) {
    return AERIAL_KNEE * (exp(w * log(1.0 + range / AERIAL_KNEE)) - 1.0);
}
