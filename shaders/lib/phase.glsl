// Phase functions of the radiometric model (atmos/phase.py hg and phase), in 1/sr.

// One Henyey-Greenstein lobe at the cosine c of the scattering angle.
float hg(float c, float g) {
    float d = max(1.0 + g * g - 2.0 * g * c, 1e-6);
    return (1.0 - g * g) / (12.566370614359172 * d * sqrt(d));
}

// The two-lobe mix (1 - w) HG(g) + w HG(g2), lobes = (g, g2, w).
float phase2(float c, vec3 lobes) {
    return mix(hg(c, lobes.x), hg(c, lobes.y), lobes.z);
}

