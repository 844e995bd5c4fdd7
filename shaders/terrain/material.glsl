// The terrain's albedo: grass on flat ground (lush or dry by broad patches), rock on slopes, snow on flat
// ground above the snowline (a fraction of the relief), broken by a detail of 2D value noise over the
// ground in twelve octaves, lattice cells of 2048 m halving down to 1 m (lib/value_noise.glsl). An octave
// fades to its mean as the pixel's footprint grows from 1/4 to 1/2 of its cell, so far ground keeps only
// what its pixels can show (no aliasing) and all of it keeps the same mean colour.
// float64 twin: plugins/terrain/material.py (tests/test_terrain.py compares them).
// Needs lib/hash.glsl and lib/value_noise.glsl included first.
#ifndef TERRAIN_MATERIAL_GLSL_INCLUDED
#define TERRAIN_MATERIAL_GLSL_INCLUDED

const int TERRAIN_OCTAVES = 12;
const int TERRAIN_BROAD = 3;           // the first three (2048, 1024, 512 m) make the broad patches
const float TERRAIN_CELL0 = 2048.0;    // m: the broadest octave's lattice cell; each next is 2x finer

// Octave i of the detail, centred on 0 (in [-0.5, 0.5)) and faded to 0 as `footprint` (m) reaches half its cell.
float terrain_octave(vec2 xz, int i, float footprint) {
    float cell = TERRAIN_CELL0 / float(1 << i);
    float fade = 1.0 - smoothstep(0.25, 0.5, footprint / cell);
    if (fade <= 0.0) return 0.0;
    vec2 offset = vec2(0.37, 0.71) * float(i);    // the octaves' lattices do not line up
    return fade * (value_noise2(xz / cell + offset, vn_key(uint(i))) - 0.5);
}

// Albedo (linear RGB in [0, 1]) of the ground at world point p (m) with unit normal n, seen with a pixel
// footprint of `footprint` m; relief (m): the hills' height scale; snowline: the height (in reliefs)
// above which flat ground is snow; rock_slope: the slope (sine of its angle) where ground is half rock.
vec3 terrain_albedo(vec3 p, vec3 n, float footprint, float relief, float snowline, float rock_slope) {
    float broad = 0.5 * terrain_octave(p.xz, 0, footprint) + 0.3 * terrain_octave(p.xz, 1, footprint)
                + 0.2 * terrain_octave(p.xz, 2, footprint);           // km patches: in [-0.5, 0.5]
    float fine = 0.0;                                                 // metres to 256 m: in [-0.675, 0.675]
    for (int i = TERRAIN_BROAD; i < TERRAIN_OCTAVES; ++i) fine += 0.15 * terrain_octave(p.xz, i, footprint);
    float slope = sqrt(max(1.0 - n.y * n.y, 0.0));
    vec3 grass = mix(vec3(0.09, 0.20, 0.05), vec3(0.25, 0.27, 0.11), clamp(0.5 + 1.6 * broad + 0.6 * fine, 0.0, 1.0));
    vec3 rock = mix(vec3(0.20, 0.18, 0.16), vec3(0.42, 0.38, 0.33), clamp(0.5 + 0.8 * broad + 1.4 * fine, 0.0, 1.0));
    vec3 snow = vec3(0.80, 0.82, 0.86);
    float rocky = smoothstep(rock_slope - 0.08, rock_slope + 0.08, slope + 0.15 * broad + 0.12 * fine);
    float h = p.y / max(relief, 1e-3);
    float snowy = smoothstep(snowline - 0.05, snowline + 0.05, h + 0.25 * broad + 0.1 * fine)
                * (1.0 - smoothstep(rock_slope, rock_slope + 0.2, slope + 0.1 * fine));
    vec3 albedo = mix(mix(grass, rock, rocky), snow, snowy);
    return clamp(albedo * (1.0 + 0.8 * fine * (1.0 - 0.7 * snowy)), 0.0, 1.0);
}
#endif
