// (1 - e^(-x)) / x for x >= 0: the mean of e^(-s) over [0, x], a homogeneous segment's light per unit of
// its optical depth x. Below 0.1 its Taylor series (truncation < 2e-8): the quotient there loses
// 6e-8 / x of its value to float cancellation (a thin segment of sky, x ~ 1e-9, came out 1e3 times too bright).
#ifndef EXP_MEAN_INCLUDED
#define EXP_MEAN_INCLUDED
float exp_mean(float x) {
    return x < 0.1 ? 1.0 - x * (0.5 - x * (1.0 / 6.0 - x * (1.0 / 24.0 - x / 120.0))) : (1.0 - exp(-x)) / x;
}

vec3 exp_mean(vec3 x) { return vec3(exp_mean(x.x), exp_mean(x.y), exp_mean(x.z)); }
#endif
