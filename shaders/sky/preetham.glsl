// Preetham, Shirley & Smits 1999 analytic daylight; float64 reference: plugins/sky/preetham.py.
// Perez F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ) for (Y, x, y) at once; value =
// zenith · F(θ, γ) / F(0, θs); xyY → XYZ → linear sRGB. Needs SKY_COS_FLOOR (views below it use it).

// Angle between unit vectors, well conditioned everywhere (asin/acos are imprecise on some GPUs).
float sky_angle(vec3 u, vec3 v) {
    return 2.0 * atan(length(u - v), length(u + v));
}

vec3 sky_perez(float T, float cos_theta, float gamma) {
    vec3 A = vec3(0.1787, -0.0193, -0.0167) * T + vec3(-1.4630, -0.2592, -0.2608);
    vec3 B = vec3(-0.3554, -0.0665, -0.0950) * T + vec3(0.4275, 0.0008, 0.0092);
    vec3 C = vec3(-0.0227, -0.0004, -0.0079) * T + vec3(5.3251, 0.2125, 0.2102);
    vec3 D = vec3(0.1206, -0.0641, -0.0441) * T + vec3(-2.5771, -0.8989, -1.6537);
    vec3 E = vec3(-0.0670, -0.0033, -0.0109) * T + vec3(0.3703, 0.0452, 0.0529);
    float cg = cos(gamma);
    return (1.0 + A * exp(B / cos_theta)) * (1.0 + C * exp(D * gamma) + E * cg * cg);
}

// (Y in kcd/m², x, y) at the zenith for turbidity T and sun zenith angle ts (radians, 0..π/2).
vec3 sky_zenith_Yxy(float T, float ts) {
    float chi = (4.0 / 9.0 - T / 120.0) * (3.14159265358979 - 2.0 * ts);
    float Y = (4.0453 * T - 4.9710) * tan(chi) - 0.2155 * T + 2.4192;
    vec4 th = vec4(ts * ts * ts, ts * ts, ts, 1.0);
    vec3 t = vec3(T * T, T, 1.0);
    float x = dot(t, vec3(dot(vec4(0.00166, -0.00375, 0.00209, 0.0), th),
                          dot(vec4(-0.02903, 0.06377, -0.03202, 0.00394), th),
                          dot(vec4(0.11693, -0.21196, 0.06052, 0.25886), th)));
    float y = dot(t, vec3(dot(vec4(0.00275, -0.00610, 0.00317, 0.0), th),
                          dot(vec4(-0.04214, 0.08970, -0.04153, 0.00516), th),
                          dot(vec4(0.15346, -0.26756, 0.06670, 0.26688), th)));
    return vec3(Y, x, y);
}

vec3 sky_xyY_to_srgb(float x, float y, float Y) {
    vec3 xyz = vec3(x / y * Y, Y, (1.0 - x - y) / y * Y);
    return max(vec3(dot(vec3(3.2406, -1.5372, -0.4986), xyz),
                    dot(vec3(-0.9689, 1.8758, 0.0415), xyz),
                    dot(vec3(0.0557, -0.2040, 1.0570), xyz)), vec3(0.0));
}

// Linear sRGB sky radiance in kcd/m² for unit view v and unit sun s; a sun below the horizon counts as on it.
vec3 sky_preetham(vec3 v, vec3 s, float T) {
    float ts = s.y > 0.0 ? atan(length(s.xz), s.y) : 1.5707963267949;
    vec3 ratio = sky_perez(T, max(v.y, SKY_COS_FLOOR), sky_angle(v, s)) / sky_perez(T, 1.0, ts);
    vec3 Yxy = sky_zenith_Yxy(T, ts) * ratio;
    return sky_xyY_to_srgb(Yxy.y, Yxy.z, Yxy.x);
}
