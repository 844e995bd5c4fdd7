// Probabilities of the cloud automaton from a region-volume value r in [0, 1] (thesis Appendix A):
// p_hum = hum_scale * r, p_act = act_scale * r, p_ext = ext_scale * (1 - r), and p_ext = 1 where
// r <= vanish_threshold (cells outside every ellipsoid lose their cloud).
// scales = (hum_scale, act_scale, ext_scale, vanish_threshold); returns (p_hum, p_act, p_ext).
vec3 weather_probabilities(float r, vec4 scales) {
    float p_ext = (r <= scales.w) ? 1.0 : scales.z * (1.0 - r);
    return vec3(scales.x * r, scales.y * r, p_ext);
}
