// The multiple-scattering octaves' sun transmittances (plugins/clouds/light/medium.py octave_transmittances):
// light that reached a point with k forward scatterings on its way from the sun, k Poisson-distributed
// with mean x = (1 - a) tau (tau = -ln T the sun's optical depth, a = ms_attenuation: the share of
// scatterings that turn light aside; the rest stay in the forward peak). (T, T x, T x^2/2): none, one,
// two; the fourth, T^a - those three, is all higher counts (their sum over every count is T^a).
vec4 octave_transmittances(float T, float a) {
    T = clamp(T, 0.0, 1.0);
    float x = -(1.0 - a) * log(max(T, 1e-30));
    vec3 low = T * vec3(1.0, x, 0.5 * x * x);
    return vec4(low, max(pow(T, a) - low.x - low.y - low.z, 0.0));
}
