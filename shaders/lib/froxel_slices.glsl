// Froxel slices along a view ray: slice coordinate w in [0, 1] <-> distance d, logarithmic beyond `knee`
// and nearly linear inside it, w = ln(1 + d / knee) / ln(1 + range / knee): even steps of the distance's
// ratio far out, no slice wasted near the camera (atmos/froxels.py is the float64 twin). The sky's aerial
// perspective (sky/aerial_slices.glsl), the volumetric fog's and the light shafts' froxels use it.
// Where in its slice a froxel fill samples in frame `frame` (the frame block's frame_index): 0 the near
// boundary, 1 the far one; frac(1/2 + frame / phi) in 32-bit fixed point (Roberts' R1 sequence, exact for any
// frame; the middle in frame 0), or the middle (0.5) where not `jittered` (atmos/froxels.py froxel_jitter).
#ifndef FROXEL_SLICES_INCLUDED
#define FROXEL_SLICES_INCLUDED
float froxel_jitter(uint frame, bool jittered) {
    return jittered ? float((2147483648u + frame * 2654435769u) >> 8u) / 16777216.0 : 0.5;
}

float froxel_w(float d, float range, float knee) {
    return log(1.0 + max(d, 0.0) / knee) / log(1.0 + range / knee);
}

float froxel_distance(float w, float range, float knee) {
    return knee * (exp(w * log(1.0 + range / knee)) - 1.0);
}

// A (W, H, D + 1) volume whose layer k holds a medium from the camera to slice boundary k, read
// trilinearly at uv and the slice of distance d (capped at range): atmos/froxels.py froxel_lookup.
vec4 froxel_read(sampler3D volume, vec2 uv, float d, float range, float knee) {
    float layers = float(textureSize(volume, 0).z);
    float w = froxel_w(min(d, range), range, knee) * (layers - 1.0);
    return textureLod(volume, vec3(uv, (w + 0.5) / layers), 0.0);
}
#endif
