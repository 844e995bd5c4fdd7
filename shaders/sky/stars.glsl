// Procedural twinkling stars hashed on the view direction; float64 reference: plugins/sky/stars.py
// (read its docstring). Needs the STAR_* defines that plugins/sky/shader.py passes.
#include "lib/hash.glsl"

float sky_unit16(uint h, uint shift) {
    return float((h >> shift) & 0xffffu) / 65535.0;
}

vec3 sky_stars(vec3 v, float sun_y, float time,  // time in [0, TWINKLE_PERIOD)
               float pixel_angle, uint threshold, float brightness,
               float twinkle) {
    float fade = (1.0 - smoothstep(STAR_NIGHT_LO, STAR_NIGHT_HI, sun_y)) * smoothstep(0.0, STAR_HORIZON, v.y);
    if (fade <= 0.0) return vec3(0.0);
    vec3 a = abs(v);
    uint face;
    vec2 uv;
    float major;
    if (a.x >= a.y && a.x >= a.z) { face = v.x > 0.0 ? 0u : 1u; uv = v.yz / a.x; major = a.x; }
    else if (a.y >= a.z) { face = v.y > 0.0 ? 2u : 3u; uv = v.xz / a.y; major = a.y; }
    else { face = v.z > 0.0 ? 4u : 5u; uv = v.xy / a.z; major = a.z; }
    float n = float(STAR_GRID);
    vec2 p = (uv * 0.5 + 0.5) * n;
    vec2 cell = clamp(floor(p), 0.0, n - 1.0);
    // the pixel's footprint in cells (the face magnifies angles by major^-1.5) widens the star
    float pixel_cells = pixel_angle * 0.5 * n / (major * sqrt(major));
    float sigma = min(sqrt(STAR_SIGMA * STAR_SIGMA + STAR_FOOTPRINT * STAR_FOOTPRINT * pixel_cells * pixel_cells),
                      STAR_SIGMA_MAX);
    vec3 total = vec3(0.0);
    for (int dy = -1; dy <= 1; dy++) {
        for (int dx = -1; dx <= 1; dx++) {
            vec2 c = cell + vec2(dx, dy);
            if (any(lessThan(c, vec2(1.0))) || any(greaterThan(c, vec2(n - 2.0)))) continue;  // borders: none
            uint counter = face * uint(STAR_GRID * STAR_GRID) + uint(c.y) * uint(STAR_GRID) + uint(c.x);
            uint h0 = atmos_hash_counter(counter, uvec2(STAR_KEY_A, STAR_KEY_B));
            if ((h0 & 0xffffu) >= threshold) continue;
            uint h1 = atmos_lowbias32(h0);
            vec2 jitter = 0.3 + 0.4 * vec2(sky_unit16(h1, 0u), sky_unit16(h1, 16u));
            float d = length(p - (c + jitter));
            if (d >= STAR_CUT_HI) continue;
            uint h2 = atmos_lowbias32(h1);
            uint h3 = atmos_lowbias32(h2);
            float profile = exp(-0.5 * (d / sigma) * (d / sigma)) * (1.0 - smoothstep(STAR_CUT_LO, STAR_CUT_HI, d));
            float bright = 0.05 + 0.95 * pow(sky_unit16(h2, 0u), 8.0);
            float cycles = float(uint(TWINKLE_CYCLES_LO) + (h3 & 0xffffu) % uint(TWINKLE_CYCLES_HI - TWINKLE_CYCLES_LO));
            float tw = 1.0 + twinkle * sin(6.28318530717959 * fract(cycles * time / TWINKLE_PERIOD + sky_unit16(h2, 16u)));
            vec3 tint = mix(vec3(1.0, 0.82, 0.65), vec3(0.75, 0.85, 1.0), sky_unit16(h3, 16u));
            total += bright * tw * profile * tint;
        }
    }
    return brightness * (STAR_SIGMA / sigma) * (STAR_SIGMA / sigma) * fade * total;
}
