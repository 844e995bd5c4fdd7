"""The Monte-Carlo path tracer (atmos.plugins.clouds.light.path_tracer) on analytic cases: the single-scattering
integral of a uniform box, the optically thin limit, a uniform slab against a discrete-ordinates
solution derived here, energy conservation at albedo 1 and the white furnace."""
import math

import numpy as np
import pytest

from atmos.plugins.clouds.light.path_tracer import phase, trace

SLAB = dict(density=np.ones((1, 1, 1)), cell=(400.0, 1.0, 400.0), lo=(-200.0, 0.0, -200.0))


def slab_reference(tau: float, albedo: float, mu0: float, layers: int = 1000, angles: int = 16):
    """(diffuse reflection, diffuse transmission) as fractions of the incident flux of a collimated
    beam (cosine mu0) on a uniform slab of optical thickness ``tau`` with isotropic scattering:
    discrete ordinates (double Gauss) with source iteration, exact per layer for a constant source."""
    x, wq = np.polynomial.legendre.leggauss(angles)
    mu, wq = 0.5 * (x + 1.0), 0.5 * wq                      # one hemisphere, weights sum to 1
    dt = tau / layers
    t = np.arange(layers + 1) * dt
    att = np.exp(-dt / mu)
    direct = albedo / (4 * math.pi) * mu0 * (np.exp(-t[:-1] / mu0) - np.exp(-t[1:] / mu0)) / dt   # E = 1
    source = direct.copy()
    for _ in range(500):
        down, up = np.zeros((layers, angles)), np.zeros((layers, angles))
        i = np.zeros(angles)
        for k in range(layers):                           # downward sweep
            out = i * att + source[k] * (1 - att)
            down[k] = source[k] + (i - out) * mu / dt      # the layer's mean intensity
            i = out
        bottom = i
        i = np.zeros(angles)
        for k in range(layers - 1, -1, -1):
            out = i * att + source[k] * (1 - att)
            up[k] = source[k] + (i - out) * mu / dt
            i = out
        top = i
        new = direct + albedo / 2.0 * ((down + up) @ wq)
        if np.abs(new - source).max() < 1e-12:
            break
        source = new
    flux = mu0                                   # incident flux of irradiance E = 1
    return 2 * math.pi * (top * mu) @ wq / flux, 2 * math.pi * (bottom * mu) @ wq / flux


def cosine_rays(rng, n, y, sign):
    u1, u2 = rng.random(n), rng.random(n)
    mu, phi = np.sqrt(u1), 2 * np.pi * u2
    s = np.sqrt(1 - mu ** 2)
    d = np.stack([s * np.cos(phi), sign * mu, s * np.sin(phi)], 1)
    o = np.stack([rng.uniform(-1, 1, n), np.full(n, y), rng.uniform(-1, 1, n)], 1)
    return o, d


@pytest.mark.parametrize("tau, albedo, mu0", [(1.0, 1.0, 1.0), (2.0, 0.9, 0.6)])
def test_uniform_slab_matches_discrete_ordinates(tau, albedo, mu0):
    rng = np.random.default_rng(7)
    sun = (math.sqrt(1 - mu0 ** 2), mu0, 0.0)
    n = 40000
    args = dict(SLAB, sigma_t=tau, albedo=albedo, sun_dir=sun, sun_irradiance=1.0, samples=1, rng=rng)
    o, d = cosine_rays(rng, n, -1e-6, 1)
    below = trace(origins=o, directions=d, **args)
    o, d = cosine_rays(rng, n, 1 + 1e-6, -1)
    above = trace(origins=o, directions=d, **args)
    # flux out per incident flux mu0 E: pi * mean radiance over cosine-weighted rays / mu0
    T = math.pi * below.radiance[:, 0].mean() / mu0
    R = math.pi * above.radiance[:, 0].mean() / mu0
    eT = math.pi * below.radiance[:, 0].std() / math.sqrt(n) / mu0
    eR = math.pi * above.radiance[:, 0].std() / math.sqrt(n) / mu0
    R_ref, T_ref = slab_reference(tau, albedo, mu0)
    assert abs(T - T_ref) < 4 * eT + 0.003, (T, T_ref, eT)
    assert abs(R - R_ref) < 4 * eR + 0.003, (R, R_ref, eR)
    if albedo == 1.0:                                 # nothing absorbed: out = in
        assert abs(R + T + math.exp(-tau / mu0) - 1.0) < 4 * math.hypot(eR, eT) + 0.003
        assert abs(R_ref + T_ref + math.exp(-tau / mu0) - 1.0) < 1e-3


def test_discrete_ordinates_reference_conserves_and_absorbs():
    R, T = slab_reference(1.0, 1.0, 1.0)
    assert R + T + math.exp(-1.0) == pytest.approx(1.0, abs=1e-3)
    R2, T2 = slab_reference(1.0, 0.5, 1.0)
    assert R2 + T2 + math.exp(-1.0) < 0.85


def single_scattering_box(L, sigma, albedo, g, sun):
    """A ray along -z at mid-height through a uniform cube [-L/2, L/2] x [0, L] x [-L/2, L/2], sun
    toward ``sun`` = (0, sy, sz): exact single scattering by quadrature along the ray."""
    s = np.linspace(0, L, 40001)
    mid = 0.5 * (s[1:] + s[:-1])
    z = 0.5 * L - mid
    to_sun = np.minimum(0.5 * L / sun[1], (0.5 * L - z) / sun[2])    # to the top face or the +z face
    integrand = np.exp(-sigma * mid) * np.exp(-sigma * to_sun)
    return albedo * sigma * phase(-sun[2], g) * integrand.sum() * (s[1] - s[0])


@pytest.mark.parametrize("sigma", [0.004, 0.4])
def test_single_scattering_and_the_thin_limit(sigma):
    L = 10.0
    rng = np.random.default_rng(3)
    box = dict(density=np.ones((1, 1, 1)), cell=(L, L, L), lo=(-5.0, 0.0, -5.0))
    o, d = np.array([[0.0, 5.0, 20.0]]), np.array([[0.0, 0.0, -1.0]])
    sun = (0.0, 0.6, 0.8)                                 # behind the eye: back scattering, cos -0.8
    want = single_scattering_box(L, sigma, 0.9, 0.6, sun)
    args = dict(box, origins=o, directions=d, sigma_t=sigma, albedo=0.9, g=0.6, sun_dir=sun,
                sun_irradiance=1.0, rng=rng)
    single = trace(max_order=1, samples=200000, **args)
    err = single.radiance_error[0, 0]
    assert abs(single.radiance[0, 0] - want) < 4 * err, (single.radiance[0, 0], want, err)
    assert abs(single.transmittance[0] - math.exp(-sigma * L)) < 4 * single.transmittance_error[0] + 1e-9
    full = trace(samples=200000, **args)
    extra = (full.radiance[0, 0] - want) / want
    # multiple scattering adds O(tau) of the single-scattered light; tau = sigma L
    if sigma * L < 0.1:
        assert abs(extra) < 0.1 + 4 * full.radiance_error[0, 0] / want
    else:
        assert extra > 0.05                          # thick enough that higher orders show


def test_white_furnace_returns_the_environment():
    """Albedo 1 in a uniform environment, no sun: every ray sees exactly the environment (radiance
    scattered + transmittance × background), for any density and phase."""
    rng = np.random.default_rng(5)
    density = rng.random((6, 4, 5)) * 2.0
    o = rng.uniform(-30, 30, (64, 3))
    target = rng.uniform([0, 0, 0], [60, 40, 50], (64, 3))
    r = trace(density, (10.0, 10.0, 10.0), (0.0, 0.0, 0.0), o, target - o, sigma_t=0.3, albedo=1.0, g=0.85,
              g2=-0.3, w=0.2, sky=0.7, ground=0.7, samples=64, rng=rng)
    total = r.radiance[:, 0] + 0.7 * r.transmittance
    assert np.abs(total - 0.7).max() < 1e-9 + 6 * 0.7 * r.transmittance_error.max()
    assert r.transmittance.min() < 0.5                # the rays did go through cloud
    absorbing = trace(density, (10.0, 10.0, 10.0), (0.0, 0.0, 0.0), o, target - o, sigma_t=0.3, albedo=0.5,
                      sky=0.7, ground=0.7, samples=64, rng=rng)
    assert (absorbing.radiance[:, 0] + 0.7 * absorbing.transmittance).mean() < 0.65


def test_phase_is_normalised_and_bad_input_is_refused():
    mu = np.linspace(-1, 1, 200001)
    p = phase(mu, 0.85, -0.2, 0.3)
    assert 2 * math.pi * p.sum() * (mu[1] - mu[0]) == pytest.approx(1.0, abs=2e-3)
    with pytest.raises(ValueError, match="density"):
        trace(-np.ones((2, 2, 2)), (1, 1, 1), (0, 0, 0), [[0, 0, -1]], [[0, 0, 1]], sigma_t=1.0)
    with pytest.raises(ValueError, match="albedo"):
        trace(np.ones((2, 2, 2)), (1, 1, 1), (0, 0, 0), [[0, 0, -1]], [[0, 0, 1]], sigma_t=1.0, albedo=2.0)
