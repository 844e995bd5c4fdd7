// Detail shaping of the marched cloud density (Nubis-style), float64 reference:
// plugins/clouds/raymarch/noise_reference.py detail_density. The textures and every uniform here are
// set by DetailNoise.bind (plugins/clouds/raymarch/noise.py); only those the program uses are set.
//
// detail_density(d, p, footprint): the smoothed automaton density d at world point p (m) gives the coverage; with
// DETAIL_OCTAVES 0 d itself, else x = d clamped to [0, 1] (NaN -> 0): where x >= K (detail_coverage,
// the density of a cloud's body) x itself (interiors stay dense); below it the coverage c = x / K is
// reshaped by the noise and scaled back by K. h = the height fraction of p in the layer (0 base, 1 top).
//   band 1 (shape, the dilation)  c = clamp((c - e) / w, 0, 1) with the threshold
//         e = min(strength (1 - shape) (0.45 + 0.55 h), 1 - w) and the width w = 1 - (1 - W) strength
//         (W = noise.py's BAND_WIDTH; the uniform detail_band_width is w): where the shape noise is high (e ~ 0) even a thin coverage becomes
//         the full body density, so the cloud grows billows out to where the automaton's density
//         fades (about a cell past its visible edge; d = 0 stays 0, so the skip map stays exact);
//         where it is low the edge is carved in. Less carving at the base (flatter bases), most at
//         the top (cauliflower tops). shape = base.r (Perlin–Worley) with 1 octave, from 2 on Nubis'
//         remap(base.r, fbm - 1, 1, 0, 1) with fbm = base.gba · (.625, .25, .125) (same fetch).
//   band 3 (detail)  c = erode(c, c B strength mix(fine, 1 - fine, clamp(3 h, 0, 1))), erode(c, e) =
//         remap(c, min(e, 0.98), 1, 0, 1), fine = the detail texture's Worley FBM (tile
//         detail_scale / 8, a second 3D read), B = detail_band_strength / strength: wispy strands at
//         the base (the FBM's cells), cauliflower billows above (its inverse). The threshold scales
//         with c, so the fine band thins a thin edge (to c (1 - e) / (1 - e c)) but never cuts it to 0:
//         a threshold of its own punched isolated pinholes through every edge, seen at 1:1.
// c = 1 stays 1 (e <= 1 - w; a core is never holed) and the result grows with d.
// footprint: the pixel's width at p (m). A band's noise finer than the pixel aliases (stripes and
// crawling jaggies on far clouds), so each band's strength is scaled by keep = detail_fade(footprint in
// its tiles): 1 up to DETAIL_FADE.x tiles, 0 from DETAIL_FADE.y (noise.py DETAIL_FADE); at 0 the band
// leaves c unchanged (strength 0: e = 0, w = 1), and with both at 0 no texture is read.
// Settings behind the uniforms (RaymarchCloudSettings): detail_scale (cells per base tile, bound in m),
// detail_strength (0..1), detail_octaves (the define), the layer's base and height (m) and the wind
// (m/s) × time both textures scroll with (the scroll is reduced to [0, 1) tiles on the CPU in
// float64: no precision loss over time).

#ifndef DETAIL_OCTAVES
#define DETAIL_OCTAVES 0
#endif

layout(binding = 12) uniform sampler3D detail_base_noise;   // RGBA8, repeat, linear
layout(binding = 13) uniform sampler3D detail_fine_noise;
layout(std140, binding = 4) uniform Detail {   // written by noise.py DetailNoise.bind (DETAIL_BLOCK), once per change
    vec3 detail_offset_base;       //  0  wind·time in base tiles, mod 1
    float detail_inv_scale;        // 12  1 / detail_scale (1/m)
    vec3 detail_offset_fine;       // 16  wind·time in detail tiles, mod 1
    float detail_inv_scale_fine;   // 28  8 / detail_scale
    vec2 detail_layer;             // 32  (base y m, 1 / height m) of the layer
    float detail_strength;         // 40  band 1's strength
    float detail_band_strength;    // 44  band 3: 0.5 detail_strength
    float detail_coverage;         // 48  K: the density at and above which nothing is eroded
    float detail_band_width;       // 52  w = 1 - (1 - W) strength: the shape band's remap width
};                                 // 64 bytes
const vec2 DETAIL_FADE = vec2(1.0 / 16.0, 0.25);   // noise.py DETAIL_FADE (pixel footprint in tiles)

float detail_fade(float tiles) {
    return 1.0 - clamp((tiles - DETAIL_FADE.x) / (DETAIL_FADE.y - DETAIL_FADE.x), 0.0, 1.0);
}

float detail_erode(float x, float e) {
    e = min(e, 0.98);                         // x = 1 stays 1 (a core is never holed)
    return clamp((x - e) / (1.0 - e), 0.0, 1.0);
}

float detail_density(float d, vec3 p, float footprint) {
#if DETAIL_OCTAVES == 0
    return d;
#else
    float x = d > 0.0 ? min(d, 1.0) : 0.0;
    float keep = detail_fade(footprint * detail_inv_scale);    // the fine band's keep is never larger
    if (x >= detail_coverage || keep <= 0.0) return x;
    float c = x / detail_coverage;
    float h = clamp((p.y - detail_layer.x) * detail_layer.y, 0.0, 1.0);
    vec4 n = textureLod(detail_base_noise, fract(p * detail_inv_scale - detail_offset_base), 0.0);
    float shape = n.r;
#if DETAIL_OCTAVES >= 2
    float fbm = dot(n.gba, vec3(0.625, 0.25, 0.125));
    shape = clamp((shape + 1.0 - fbm) / (2.0 - fbm), 0.0, 1.0);
#endif
    float w = 1.0 - (1.0 - detail_band_width) * keep;
    c = clamp((c - min(keep * detail_strength * (1.0 - shape) * (0.45 + 0.55 * h), 1.0 - w)) / w, 0.0, 1.0);
#if DETAIL_OCTAVES >= 3
    vec3 f = textureLod(detail_fine_noise, fract(p * detail_inv_scale_fine - detail_offset_fine), 0.0).rgb;
    float fine = dot(f, vec3(0.625, 0.25, 0.125));
    float keep_fine = detail_fade(footprint * detail_inv_scale_fine);
    c = detail_erode(c, c * keep_fine * detail_band_strength * mix(fine, 1.0 - fine, clamp(3.0 * h, 0.0, 1.0)));
#endif
    return detail_coverage * c;
#endif
}
