// The volumetric fog's FBM (lib/value_noise.glsl value_fbm: its octaves, rotation, lacunarity and
// weights) on a lattice that repeats every FOG_LATTICE cells per axis (VolumetricFogSettings.noise):
//   FOG_NOISE_FILTERED 1: the lattice baked once per seed into the r32f texture fog_lattice
//     (volumetric_fog/lattice.comp), one trilinear fetch per octave at the smoothstep-warped coordinate
//     floor(x) + f²(3 - 2f) + 1/2 (the texture unit's blend weights: 8 fraction bits on NVIDIA);
//   0: the 8 corners hashed (vn_lattice3 of the cell mod FOG_LATTICE) and blended in float32.
// float64 twin: atmos/value_noise.py fbm(..., period=FOG_LATTICE).
#if FOG_NOISE_FILTERED
layout(binding = 6) uniform sampler3D fog_lattice;
#else
uniform uint seed;
#endif

float lattice_noise(vec3 x, uint key) {
    vec3 p = floor(x);
    vec3 f = x - p;
    f = f * f * (3.0 - 2.0 * f);
#if FOG_NOISE_FILTERED
    const float n = float(FOG_LATTICE);
    vec3 w = p - n * floor(p / n);                // the cell mod n: exact for integral p
    return texture(fog_lattice, (w + f + 0.5) / n).r;
#else
    ivec3 c = ivec3(p) & (FOG_LATTICE - 1), e = (c + 1) & (FOG_LATTICE - 1);
    return mix(mix(mix(vn_lattice3(c, key), vn_lattice3(ivec3(e.x, c.y, c.z), key), f.x),
                   mix(vn_lattice3(ivec3(c.x, e.y, c.z), key), vn_lattice3(ivec3(e.x, e.y, c.z), key), f.x), f.y),
               mix(mix(vn_lattice3(ivec3(c.x, c.y, e.z), key), vn_lattice3(ivec3(e.x, c.y, e.z), key), f.x),
                   mix(vn_lattice3(ivec3(c.x, e.y, e.z), key), vn_lattice3(e, key), f.x), f.y),
               f.z);
#endif
}

// value_fbm's sum with lattice_noise for each octave (octaves clamped to 0..16; an octave whose
// coordinates reach VN_LIMIT ends the sum, as there).
float lattice_fbm(vec3 p, int octaves) {
#if FOG_NOISE_FILTERED
    uint key = 0u;                                // the texture holds the seed's lattice
#else
    uint key = vn_key(seed);
#endif
    float total = 0.0;
    float amp = 1.0;
    int n = clamp(octaves, 0, 16);
    for (int i = 0; i < n; ++i) {
        if (any(greaterThanEqual(abs(p), vec3(VN_LIMIT)))) break;
        amp *= 0.5;
        total += amp * lattice_noise(p, key);
        p = VN_ROTATION * p * (2.0 + float(i) / 10.0);
    }
    return total;
}
