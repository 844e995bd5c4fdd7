// Value noise on an integer lattice with smoothstep interpolation, and the rotated FBM of
// fbm-raymarched-fog.txt. Lattice values come from lowbias32 (lib/hash.glsl), so they equal
// atmos/plugins/volumetric_fog/reference.py (and sky_layer/reference.py) bit for bit; needs
// lib/hash.glsl included first.
//   lattice value = lowbias32(...lowbias32(lowbias32(x ^ key) ^ y)... ^ w) >> 8, / 2^24, in [0, 1)

const float VN_SCALE = 1.0 / 16777216.0;

uint vn_key(uint seed) { return atmos_lowbias32(seed ^ 0x9e3779b9u); }

float vn_lattice2(ivec2 c, uint key) {
    uint h = atmos_lowbias32(uint(c.x) ^ key);
    h = atmos_lowbias32(h ^ uint(c.y));
    return float(h >> 8) * VN_SCALE;
}

float vn_lattice3(ivec3 c, uint key) {
    uint h = atmos_lowbias32(uint(c.x) ^ key);
    h = atmos_lowbias32(h ^ uint(c.y));
    h = atmos_lowbias32(h ^ uint(c.z));
    return float(h >> 8) * VN_SCALE;
}

float vn_lattice4(ivec4 c, uint key) {
    uint h = atmos_lowbias32(uint(c.x) ^ key);
    h = atmos_lowbias32(h ^ uint(c.y));
    h = atmos_lowbias32(h ^ uint(c.z));
    h = atmos_lowbias32(h ^ uint(c.w));
    return float(h >> 8) * VN_SCALE;
}

// 2D value noise in [0, 1): bilinear blend of the 4 corner values with weights f*f*(3-2f).
float value_noise2(vec2 x, uint key) {
    vec2 p = floor(x);
    vec2 f = x - p;
    f = f * f * (3.0 - 2.0 * f);
    ivec2 c = ivec2(p);
    return mix(mix(vn_lattice2(c, key), vn_lattice2(c + ivec2(1, 0), key), f.x),
               mix(vn_lattice2(c + ivec2(0, 1), key), vn_lattice2(c + ivec2(1, 1), key), f.x), f.y);
}

// 3D value noise in [0, 1): trilinear blend of the 8 corner values with weights f*f*(3-2f).
float value_noise3(vec3 x, uint key) {
    vec3 p = floor(x);
    vec3 f = x - p;
    f = f * f * (3.0 - 2.0 * f);
    ivec3 c = ivec3(p);
    return mix(mix(mix(vn_lattice3(c, key), vn_lattice3(c + ivec3(1, 0, 0), key), f.x),
                   mix(vn_lattice3(c + ivec3(0, 1, 0), key), vn_lattice3(c + ivec3(1, 1, 0), key), f.x), f.y),
               mix(mix(vn_lattice3(c + ivec3(0, 0, 1), key), vn_lattice3(c + ivec3(1, 0, 1), key), f.x),
                   mix(vn_lattice3(c + ivec3(0, 1, 1), key), vn_lattice3(c + ivec3(1, 1, 1), key), f.x), f.y),
               f.z);
}

// 4D value noise in [0, 1): the 16 corners blended axis by axis (x, then y, z, w).
float value_noise4(vec4 x, uint key) {
    vec4 p = floor(x);
    vec4 f = x - p;
    f = f * f * (3.0 - 2.0 * f);
    ivec4 c = ivec4(p);
    float w[2];
    for (int l = 0; l < 2; ++l) {
        float z[2];
        for (int k = 0; k < 2; ++k) {
            ivec4 b = c + ivec4(0, 0, k, l);
            z[k] = mix(mix(vn_lattice4(b, key), vn_lattice4(b + ivec4(1, 0, 0, 0), key), f.x),
                       mix(vn_lattice4(b + ivec4(0, 1, 0, 0), key), vn_lattice4(b + ivec4(1, 1, 0, 0), key), f.x),
                       f.y);
        }
        w[l] = mix(z[0], z[1], f.z);
    }
    return mix(w[0], w[1], f.w);
}

// Rotation between octaves (orthonormal; columns as written, GLSL column-major).
const mat3 VN_ROTATION = mat3(0.00, 0.80, 0.60,
                              -0.80, 0.36, -0.48,
                              -0.60, -0.48, 0.64);

// FBM: amplitude halves per octave (1/2, 1/4, ...); p <- R * p * (2 + i/10) after octave i.
// Result in [0, 1 - 2^-octaves); octaves is clamped to 0..16. Octaves whose coordinates leave the
// int range (|p| >= 2^31, where int() is undefined) are dropped, so huge inputs never give NaN.
const float VN_LIMIT = 2147483520.0;  // largest float below 2^31

float value_fbm(vec3 p, int octaves, uint key) {
    float f = 0.0;
    float amp = 1.0;
    int n = clamp(octaves, 0, 16);
    for (int i = 0; i < n; ++i) {
        if (any(greaterThanEqual(abs(p), vec3(VN_LIMIT)))) break;
        amp *= 0.5;
        f += amp * value_noise3(p, key);
        p = VN_ROTATION * p * (2.0 + float(i) / 10.0);
    }
    return f;
}
