"""A brute-force Monte-Carlo path tracer of the spherical atmosphere (numpy): all orders of scattering,
the reference Hillaire's multiple-scattering approximation (:mod:`.atmosphere`) is measured against.

Independent of the LUTs and of Ψms: paths start at the camera (radius ``Rg + altitude``) along the
view ray and are tracked through the shell by delta tracking (per colour channel, majorant = the
sum of the coefficients at their densities' peaks); at each real collision the weight takes the
single-scattering albedo σs/σt, next-event estimation adds the sun's light
``E p(ν) T_sun v`` (the mixed Rayleigh + Mie phase σR pR + σM pM over σs; ``T_sun`` the optical
depth to the top integrated directly, ``v`` the planet's shadow softened over the sun's disc as the
model's) and the new direction is sampled from the phase (Rayleigh by inverting its CDF, Mie's
Henyey–Greenstein exactly). The ground is Lambertian: next-event estimation of ``albedo / π E cos``,
then a cosine-weighted bounce. ``max_orders`` stops after that many scattering events (1: single
scattering only, the optically-thin check).
"""
from __future__ import annotations

import math

import numpy as np

import atmos.plugins.sky.atmosphere as ref
from atmos.plugins.sky.atmosphere_settings import AtmosphereSettings

SUN_STEPS = 128      # midpoint steps of the optical depth toward the sun per collision


def _sphere_exit(p: np.ndarray, d: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """(hit, distance) of the nearest positive intersection of rays p + t d with the sphere ``radius``."""
    b = np.einsum("ij,ij->i", p, d)
    c = np.einsum("ij,ij->i", p, p) - radius * radius
    disc = b * b - c
    sq = np.sqrt(np.maximum(disc, 0.0))
    t0, t1 = -b - sq, -b + sq
    t = np.where(t0 > 1e-6, t0, t1)
    return (disc >= 0) & (t > 1e-6), np.where((disc >= 0) & (t > 1e-6), t, np.inf)


def _basis_rotate(d: np.ndarray, mu: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Directions at cos ``mu`` from ``d`` (n, 3) and azimuth ``phi`` round it."""
    a = np.where(np.abs(d[:, [0]]) < 0.9, np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]]))
    t1 = np.cross(d, a)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(d, t1)
    s = np.sqrt(np.maximum(1.0 - mu * mu, 0.0))[:, None]
    return mu[:, None] * d + s * (np.cos(phi)[:, None] * t1 + np.sin(phi)[:, None] * t2)


def _sample_rayleigh(u: np.ndarray) -> np.ndarray:
    z = 4.0 * u - 2.0
    w = np.sqrt(z * z + 1.0)
    return np.clip(np.cbrt(z + w) + np.cbrt(z - w), -1.0, 1.0)


def _sample_hg(g: float, u: np.ndarray) -> np.ndarray:
    if abs(g) < 1e-4:
        return 1.0 - 2.0 * u
    s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u)
    return np.clip((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0)


def _sun_light(m: dict, p: np.ndarray, sun: np.ndarray) -> np.ndarray:
    """(n, 3) transmittance to the top toward the sun × the soft planet shadow, at points ``p``."""
    r = np.linalg.norm(p, axis=1)
    mu_s = np.clip(p @ sun / r, -1.0, 1.0)
    mu = np.maximum(mu_s, ref.horizon_mu(m["rg"], r))
    depth = ref.optical_depth(m, r, mu, ref.distance_to_top(m["rt"], r, mu), SUN_STEPS)
    return np.exp(-depth) * ref.sun_visibility(m["rg"], r, mu_s)[:, None]


def trace(view_dir, sun_dir, altitude: float = 0.0, settings: AtmosphereSettings | None = None,
          paths: int = 20000, seed: int = 0, max_orders: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """(radiance (3,), its standard error (3,)) along the unit ``view_dir`` from ``altitude`` m for the
    unit ``sun_dir`` (y up), ``paths`` paths per colour channel, in the units of :func:`ref.sky_radiance`."""
    settings = settings or AtmosphereSettings()
    m = ref.medium(settings)
    rng = np.random.default_rng(seed)
    v = ref.unit(view_dir)
    s = ref.unit(sun_dir)
    mean, err = np.zeros(3), np.zeros(3)
    for c in range(3):
        total = _trace_channel(m, c, v, s, ref.camera_radius(m, altitude), paths, rng, max_orders)
        mean[c] = total.mean() * m["sun"][c]
        err[c] = total.std() / math.sqrt(paths) * m["sun"][c]
    return mean, err


def _trace_channel(m, c, v, s, r0, n, rng, max_orders) -> np.ndarray:
    ray, mie_s, mie_t, oz = m["ray"][c], m["mie_s"][c], m["mie_t"][c], m["ozone"][c]
    majorant = ray + mie_t + oz
    pos = np.tile([0.0, r0, 0.0], (n, 1))
    d = np.tile(v, (n, 1))
    w = np.ones(n)
    order = np.zeros(n, int)
    total = np.zeros(n)
    alive = np.arange(n)
    if majorant <= 0:
        return total
    while alive.size:
        p, dd = pos[alive], d[alive]
        step = -np.log(1.0 - rng.random(alive.size)) / majorant
        _, t_top = _sphere_exit(p, dd, m["rt"])
        hit_g, t_g = _sphere_exit(p, dd, m["rg"])
        t_bound = np.minimum(t_top, np.where(hit_g, t_g, np.inf))
        inside = step < t_bound
        # leaving through the top: the path ends; reaching the ground: a Lambertian bounce
        ground = ~inside & hit_g & (t_g <= t_top)
        gi = alive[ground]
        if gi.size:
            q = p[ground] + t_g[ground, None] * dd[ground]
            nrm = q / np.linalg.norm(q, axis=1, keepdims=True)
            q = nrm * (m["rg"] + 1e-3)
            cos_s = np.maximum(nrm @ s, 0.0)
            total[gi] += w[gi] * m["albedo"][c] / math.pi * cos_s * _sun_light(m, q, s)[:, c]
            w[gi] *= m["albedo"][c]
            order[gi] += 1
            pos[gi] = q
            d[gi] = _basis_rotate(nrm, np.sqrt(rng.random(gi.size)), 2 * math.pi * rng.random(gi.size))
        keep = inside | ground
        ci = alive[inside]
        if ci.size:
            q = p[inside] + step[inside, None] * dd[inside]
            r = np.linalg.norm(q, axis=1)
            s_r, s_m, ext = (a[:, c] for a in ref.coefficients(m, r))
            real = rng.random(ci.size) * majorant < ext
            ri, q, s_r, s_m, ext = ci[real], q[real], s_r[real], s_m[real], ext[real]
            pos[ci] = p[inside] + step[inside, None] * dd[inside]
            if ri.size:
                sig_s = s_r + s_m
                w[ri] *= np.where(ext > 0, sig_s / np.maximum(ext, 1e-300), 0.0)
                nu = d[ri] @ s
                phase = (s_r * ref.rayleigh_phase(nu) + s_m * ref.hg_phase(m["g"], nu)) / np.maximum(sig_s, 1e-300)
                total[ri] += w[ri] * phase * _sun_light(m, q, s)[:, c]
                order[ri] += 1
                use_r = rng.random(ri.size) * np.maximum(sig_s, 1e-300) < s_r
                mu = np.where(use_r, _sample_rayleigh(rng.random(ri.size)), _sample_hg(m["g"], rng.random(ri.size)))
                d[ri] = _basis_rotate(d[ri], mu, 2 * math.pi * rng.random(ri.size))
        alive = alive[keep]
        alive = alive[(order[alive] < max_orders) & (w[alive] > 1e-4)]
    return total
