// Depth-aware upsampling of a low-resolution layer (atmos/offscreen.py's composite and
// the ray march's temporal resolve; numpy twin: offscreen_reference.upsample_weights). The four
// low-res texels around p (texel centres at integers, clamped to the edge) with bilinear weights,
// unless one saw a scene whose view depth differs from this pixel's by more than `edge` (relative):
// a geometry edge, where all the weight goes to the texel nearest in depth (the first of equals), so
// the layer neither bleeds over near geometry nor leaves gaps beside it.
// inv_pixel, low_depth's texels: 1 / view depth (upsample_inv_depth of a window depth).

float upsample_inv_depth(float window_depth, vec2 inv_near_far) {   // (1/near, 1/far): linear in window depth
    return mix(inv_near_far.x, inv_near_far.y, window_depth);
}

// last: the low-res target's last texel
void upsample_taps(sampler2D low_depth, ivec2 last, vec2 p, float inv_pixel, vec2 inv_near_far, float edge,
                   out ivec2 taps[4], out float weights[4]) {
    ivec2 p0 = ivec2(floor(p));
    vec2 f = p - vec2(p0);
    float best = 1e30;
    int nearest = 0;
    bool is_edge = false;
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        taps[k] = clamp(p0 + o, ivec2(0), last);
        vec2 b = mix(1.0 - f, f, vec2(o));
        weights[k] = b.x * b.y;
        float wq = upsample_inv_depth(texelFetch(low_depth, taps[k], 0).r, inv_near_far);
        float rel = abs(inv_pixel - wq) / max(min(inv_pixel, wq), 1e-30);    // |z - zq| / min(z, zq)
        is_edge = is_edge || rel > edge;
        if (rel < best) { best = rel; nearest = k; }
    }
    if (is_edge)
        for (int k = 0; k < 4; ++k) weights[k] = k == nearest ? 1.0 : 0.0;
}
