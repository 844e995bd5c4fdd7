// The sun's disc and its glare (float64 twin: atmos/sun_disc.py sun_disc; SUN_LIMB, LIMB_FLOOR,
// GLARE_REACH, EDGE_MIN are its SUN_DISC_DEFINES): for unit view v and sun s, the radiance per unit of
// the sun's colour: `gain` at the centre, limb-darkened, antialiased over `pixel_angle` (radians per
// pixel), and a glare of `glare` × the centre at the edge falling as 1/angle² beyond it. `chord`: |v − s|
// of the disc's angular radius.
vec3 sun_disc(vec3 v, vec3 s, float chord, float gain, float glare, float pixel_angle) {
    float c = length(v - s);
    float r = chord;
    float half_edge = 0.5 * max(pixel_angle, EDGE_MIN * r);
    float cover = 1.0 - smoothstep(r - half_edge, r + half_edge, c);
    float mu = sqrt(max(1.0 - (c / r) * (c / r), LIMB_FLOOR * LIMB_FLOOR));
    float halo = glare * (r / max(c, r)) * (r / max(c, r)) * (1.0 - smoothstep(0.0, GLARE_REACH, c));
    return gain * (cover * pow(vec3(mu), SUN_LIMB) + halo);
}
