// Phase functions of the radiometric model (atmos/shading/medium.py hg and phase), in 1/sr.

// One Henyey-Greenstein lobe at the cosine c of the scattering angle.
float hg(float c, float g) {
    float d = max(1.0 + g * g - 2.0 * g * c, 1e-6);
    return (1.0 - g * g) / (12.566370614359172 * d * sqrt(d));
}

// The two-lobe mix (1 - w) HG(g) + w HG(g2), lobes = (g, g2, w).
float phase2(float c, vec3 lobes) {
    return mix(hg(c, lobes.x), hg(c, lobes.y), lobes.z);
}

// The share of one HG lobe's light, scattered into a direction d, that came from the hemisphere about d
// (medium.hemisphere_share): (1 - g^2) / 2g (1 / (1 - g) - 1 / sqrt(1 + g^2)), 1/2 at g = 0.
float hg_hemisphere(float g) {
    if (abs(g) < 1e-4) return 0.5 + 0.375 * g;
    return (1.0 - g * g) / (2.0 * g) * (1.0 / (1.0 - g) - inversesqrt(1.0 + g * g));
}

// The two-lobe mix's share, lobes = (g, g2, w).
float hemisphere_share(vec3 lobes) {
    return mix(hg_hemisphere(lobes.x), hg_hemisphere(lobes.y), lobes.z);
}
