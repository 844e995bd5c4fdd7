// The fog's in-scattered colour in_color(dir) (fog.frag; the light shafts' march subtracts a share of it):
// fog_color, or with FOG_SKY_COLOR 1 fog_color × the sky's horizon radiance in the ray's azimuth
// (plugins/fog/sky_color.py sky_fog_color is the reference).
uniform vec3 fog_color;
#if FOG_SKY_COLOR
uniform vec3 fog_horizon[FOG_HORIZON_SAMPLES];   // sky radiance at azimuths 2π i / n (atan2(x, -z))
vec3 in_color(vec3 dir) {
    float u = fract(atan(dir.x, -dir.z) / 6.28318530718) * float(FOG_HORIZON_SAMPLES);
    int i0 = int(floor(u)) % FOG_HORIZON_SAMPLES;
    return fog_color * mix(fog_horizon[i0], fog_horizon[(i0 + 1) % FOG_HORIZON_SAMPLES], u - floor(u));
}
#else
vec3 in_color(vec3 dir) { return fog_color; }
#endif
