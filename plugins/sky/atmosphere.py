"""The physical sky after Hillaire 2020 in float64 numpy: the reference the GPU LUTs are held to.

A spherical planet of radius ``Rg`` under an atmosphere up to ``Rt`` (:class:`AtmosphereSettings`):
Rayleigh and Mie scattering with exponential densities, Mie and ozone (tent profile) absorption, a
Lambertian ground. Every quantity is a function of the radius ``r`` of a point and cosines against
the local zenith (``mu`` of a view ray, ``mu_s`` of the sun) and between view and sun (``nu``), so
a ray needs no vectors: at distance t, ``r(t) = sqrt(r² + t² + 2 r mu t)`` and
``mu_s(t) = (r mu_s + t nu) / r(t)``.

Three look-up tables, as ``shaders/sky/*.comp`` make them:

- **transmittance** (``TRANSMITTANCE_SIZE``, Bruneton's mapping of (r, mu) for rays that miss the
  ground): the optical depth ``∫ σt`` to the top (``TRANSMITTANCE_STEPS`` midpoint steps; T = e^(−τ)
  after the filter: at a grazing sun T drops by orders of magnitude between texels, τ does not).
- **multiple scattering** Ψms (``MS_SIZE``², over mu_s, squashed toward the horizon, and r):
  Hillaire's isotropic approximation:
  from each point the second order ``L2 = mean over MS_DIRECTIONS² directions of the single
  scattering of a sun of illuminance 1 with an isotropic phase`` (ground bounce included) and the
  transfer ``f = mean of ∫ σs T dt`` (the share of light scattered back to the point), summed over
  all orders as ``Ψ = L2 / (1 − f)``.
- **sky view** (``SKY_VIEW_SIZE``, azimuth from the sun × view zenith angle, the latitude squashed
  toward the horizon) of the radiance seen from the camera's altitude for the current sun.

Radiance along a ray (:func:`integrate`): ``STEPS`` segments spaced quadratically (fine near the
camera, where the air is dense), each lit at its midpoint by ``S = E (v T_sun (σR pR + σM pM) +
w Ψ σs)`` and integrated over the segment exactly for a constant medium,
``S (1 − e^(−σt Δt)) / σt``; ``v`` is the planet's shadow, softened over the sun's disc
(``SUN_EDGE``); ``w`` = ``multiple_scattering``; ``E = sun_intensity × sun_color`` (the
irradiance; ``Sun.color`` is ``sun_color × T_sun``). A ray that ends on the ground adds the ground's
sunlit radiance ``albedo / π · E T_sun max(mu_s, 0)`` times the transmittance to it. Lookups are
bilinear between texel centres with clamped edges, as the GPU's.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from atmos.plugins.sky.atmosphere_settings import AtmosphereSettings

TRANSMITTANCE_SIZE = (256, 64)      # (mu, r)
TRANSMITTANCE_STEPS = 40
MS_SIZE = 32                        # (mu_s, r)
MS_DIRECTIONS = 8                   # 8 × 8 directions per texel
MS_STEPS = 20
SKY_VIEW_SIZE = (192, 108)          # (azimuth, zenith)
SKY_VIEW_STEPS = 32
SUN_EDGE = math.sin(math.radians(0.2665))   # the sun's angular radius: the planet's shadow edge is this soft
RADIUS_EPS = 1.0                    # points are kept this far (m) inside [Rg, Rt]


def medium(settings: AtmosphereSettings) -> dict:
    """The coefficients as float64 arrays (3,), radii and heights as floats (a new dict; the arrays,
    worked out once per settings, are read-only)."""
    return dict(_medium(settings))


@lru_cache(maxsize=8)
def _medium(settings: AtmosphereSettings) -> dict:
    s = settings
    m = dict(rg=s.planet_radius, rt=s.top_radius, ray=np.array(s.rayleigh_scattering, np.float64),
                mie_s=np.array(s.mie_scattering, np.float64),
                mie_t=np.array(s.mie_scattering, np.float64) + np.array(s.mie_absorption, np.float64),
                ozone=np.array(s.ozone_absorption, np.float64), hr=s.rayleigh_scale_height,
                hm=s.mie_scale_height, oz_c=s.ozone_altitude, oz_w=0.5 * s.ozone_width, g=s.mie_g,
                albedo=np.array(s.ground_albedo, np.float64), color=np.array(s.sun_color, np.float64),
                sun=np.array(s.sun_color, np.float64) * s.sun_intensity,
                ms=s.multiple_scattering)
    for value in m.values():
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
    return m


def coefficients(m: dict, r):
    """(σs Rayleigh, σs Mie, σt), each (..., 3), at radii ``r``."""
    h = np.asarray(r, np.float64)[..., None] - m["rg"]
    dr = np.exp(-np.maximum(h, 0.0) / m["hr"])
    dm = np.exp(-np.maximum(h, 0.0) / m["hm"])
    do = np.maximum(0.0, 1.0 - np.abs(h - m["oz_c"]) / m["oz_w"])
    ray, mie = m["ray"] * dr, m["mie_s"] * dm
    return ray, mie, m["ray"] * dr + m["mie_t"] * dm + m["ozone"] * do


def rayleigh_phase(nu):
    return 3.0 / (16.0 * math.pi) * (1.0 + np.asarray(nu, np.float64) ** 2)


def hg_phase(g: float, nu):
    nu = np.asarray(nu, np.float64)
    return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * nu) ** 1.5)


def _discriminant(radius: float, r, mu):
    """r² (mu² − 1) + R², written as (R − r)(R + r) + (r mu)² (float32 keeps it on the GPU)."""
    return (radius - r) * (radius + r) + (r * mu) ** 2


def distance_to_top(rt: float, r, mu):
    r, mu = np.asarray(r, np.float64), np.asarray(mu, np.float64)
    return np.maximum(-r * mu + np.sqrt(np.maximum(_discriminant(rt, r, mu), 0.0)), 0.0)


def hits_ground(rg: float, r, mu):
    r, mu = np.asarray(r, np.float64), np.asarray(mu, np.float64)
    return (mu < 0.0) & (_discriminant(rg, r, mu) >= 0.0)


def distance_to_ground(rg: float, r, mu):
    r, mu = np.asarray(r, np.float64), np.asarray(mu, np.float64)
    return np.maximum(-r * mu - np.sqrt(np.maximum(_discriminant(rg, r, mu), 0.0)), 0.0)


def ray_end(m: dict, r, mu):
    """(ends on the ground, distance to that end or to the top of the atmosphere) of rays from ``r``."""
    ground = hits_ground(m["rg"], r, mu)
    return ground, np.where(ground, distance_to_ground(m["rg"], r, mu), distance_to_top(m["rt"], r, mu))


def horizon_mu(rg: float, r):
    """cos of the zenith angle of the ray tangent to the ground from radius ``r``."""
    r = np.asarray(r, np.float64)
    return -np.sqrt(np.maximum((r - rg) * (r + rg), 0.0)) / r


def sun_visibility(rg: float, r, mu_s):
    """0 in the planet's shadow, 1 outside, smooth over the sun's disc."""
    t = np.minimum(np.maximum((np.asarray(mu_s, np.float64) - horizon_mu(rg, r)) / SUN_EDGE * 0.5 + 0.5, 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


def to_sub_uv(x, n: int):
    return 0.5 / n + np.asarray(x, np.float64) * (1.0 - 1.0 / n)


def from_sub_uv(u, n: int):
    return (np.asarray(u, np.float64) - 0.5 / n) / (1.0 - 1.0 / n)


def texel_centres(n: int) -> np.ndarray:
    return (np.arange(n) + 0.5) / n


def bilinear(lut: np.ndarray, u, v) -> np.ndarray:
    """(..., C) of ``lut`` (H, W, C) at texture coordinates u, v in [0, 1] (texel centres at (i + ½)/n,
    clamped at the edges), as a GPU's linear filter with clamp-to-edge."""
    h, w = lut.shape[:2]
    x = np.minimum(np.maximum(np.asarray(u, np.float64) * w - 0.5, 0.0), w - 1.0)     # clips in ufuncs (per frame)
    y = np.minimum(np.maximum(np.asarray(v, np.float64) * h - 0.5, 0.0), h - 1.0)
    x0, y0 = np.minimum(np.floor(x).astype(int), w - 2), np.minimum(np.floor(y).astype(int), h - 2)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    return ((1 - fy) * ((1 - fx) * lut[y0, x0] + fx * lut[y0, x0 + 1])
            + fy * ((1 - fx) * lut[y0 + 1, x0] + fx * lut[y0 + 1, x0 + 1]))


# --- transmittance -------------------------------------------------------------------------------

def transmittance_uv(m: dict, r, mu, size=TRANSMITTANCE_SIZE):
    """(u, v) in the transmittance LUT (``size`` (w, h)) of the ray from radius ``r`` with zenith cosine ``mu``."""
    rg, rt = m["rg"], m["rt"]
    big_h = math.sqrt(rt * rt - rg * rg)
    rho = np.sqrt(np.maximum(np.asarray(r, np.float64) ** 2 - rg * rg, 0.0))
    d = distance_to_top(rt, r, mu)
    d_min, d_max = rt - np.asarray(r, np.float64), rho + big_h
    x_mu = np.where(d_max > d_min, (d - d_min) / np.maximum(d_max - d_min, 1e-9), 0.0)
    w, h = size
    return (to_sub_uv(np.minimum(np.maximum(x_mu, 0.0), 1.0), w),
            to_sub_uv(np.minimum(np.maximum(rho / big_h, 0.0), 1.0), h))


def transmittance_params(m: dict, u, v, size=TRANSMITTANCE_SIZE):
    """(r, mu) of LUT coordinates (u, v): the inverse of :func:`transmittance_uv`."""
    rg, rt = m["rg"], m["rt"]
    w, h = size
    x_mu, x_r = np.clip(from_sub_uv(u, w), 0, 1), np.clip(from_sub_uv(v, h), 0, 1)
    big_h = math.sqrt(rt * rt - rg * rg)
    rho = big_h * x_r
    r = np.sqrt(rho * rho + rg * rg)
    d_min, d_max = rt - r, rho + big_h
    d = d_min + x_mu * (d_max - d_min)
    mu = np.where(d == 0.0, 1.0, (big_h * big_h - rho * rho - d * d) / np.maximum(2.0 * r * d, 1e-9))
    return r, np.clip(mu, -1.0, 1.0)


def optical_depth(m: dict, r, mu, length, steps: int):
    """(..., 3) ∫ σt over ``length`` along the ray, ``steps`` midpoint steps."""
    r, mu = np.asarray(r, np.float64)[..., None], np.asarray(mu, np.float64)[..., None]
    length = np.asarray(length, np.float64)[..., None]
    t = (np.arange(steps) + 0.5) / steps * length
    ri = np.sqrt(np.maximum(r * r + t * t + 2.0 * r * mu * t, 0.0))
    return (coefficients(m, ri)[2] * (length / steps)[..., None]).sum(axis=-2)


def transmittance_lut(settings: AtmosphereSettings, steps: int = TRANSMITTANCE_STEPS,
                      size=TRANSMITTANCE_SIZE) -> np.ndarray:
    """(64, 256, 3) the optical depth τ to the top of the atmosphere, T = e^(−τ) (what
    transmittance.comp makes: τ, not T, so that the linear filter between texels stays accurate where
    T falls by orders of magnitude from one texel to the next, at a grazing sun)."""
    m = medium(settings)
    w, h = size
    u, v = np.meshgrid(texel_centres(w), texel_centres(h))
    r, mu = transmittance_params(m, u, v, size)
    return optical_depth(m, r, mu, distance_to_top(m["rt"], r, mu), steps)


def transmittance_to_sun(m: dict, tlut: np.ndarray, r, mu_s):
    """(..., 3) T to the top toward the sun × the planet's shadow (a ray into the ground reads the
    horizon's texel: the LUT holds only rays that miss it)."""
    u, v = transmittance_uv(m, r, np.maximum(mu_s, horizon_mu(m["rg"], r)), tlut.shape[1::-1])
    return np.exp(-bilinear(tlut, u, v)) * sun_visibility(m["rg"], r, mu_s)[..., None]


# --- radiance along a ray ---------------------------------------------------------------------------

def ms_mu_s(x):
    """mu_s of the multiple-scattering LUT's u axis (x in [0, 1]): squashed toward the horizon,
    mu_s = sign(t) t² with t = 2x − 1, where the planet's shadow makes Ψ change fastest."""
    t = 2.0 * np.asarray(x, np.float64) - 1.0
    return np.sign(t) * t * t


def ms_uv(m: dict, r, mu_s, n: int = MS_SIZE):
    mu_s = np.minimum(np.maximum(np.asarray(mu_s, np.float64), -1.0), 1.0)
    return (to_sub_uv(np.minimum(np.maximum(0.5 * np.sign(mu_s) * np.sqrt(np.abs(mu_s)) + 0.5, 0.0), 1.0), n),
            to_sub_uv(np.minimum(np.maximum((np.asarray(r, np.float64) - m["rg"]) / (m["rt"] - m["rg"]), 0.0), 1.0), n))


def clamp_radius(m: dict, r):
    return np.minimum(np.maximum(np.asarray(r, np.float64), m["rg"] + RADIUS_EPS), m["rt"] - RADIUS_EPS)   # a clip in ufuncs


def march(m: dict, tlut: np.ndarray, r, mu, mu_s, nu, t_max, steps: int, mslut: np.ndarray | None = None,
          isotropic: bool = False):
    """(radiance (..., 3) per unit sun, transfer (..., 3), throughput (..., 3)) over the first ``t_max``
    metres of rays from radius ``r``: in-scattered sunlight (``isotropic``: the multiple-scattering
    LUT's pass, isotropic phase, no Ψ; else the real phases and ``mslut``'s Ψ), ``f`` = ∫ σs T dt and the
    rays' transmittance. ``shaders/sky/atmosphere.glsl`` atm_march is the same."""
    mu, mu_s, nu, t_max = (np.broadcast_to(np.asarray(a, np.float64), r.shape) for a in (mu, mu_s, nu, t_max))
    if isotropic:
        phase_r = phase_m = np.full(r.shape, 1.0 / (4.0 * math.pi))
    else:
        phase_r, phase_m = rayleigh_phase(nu), hg_phase(m["g"], nu)
    radiance = np.zeros(r.shape + (3,))
    transfer = np.zeros(r.shape + (3,))
    throughput = np.ones(r.shape + (3,))
    for i in range(steps):
        t0, t1 = t_max * (i / steps) ** 2, t_max * ((i + 1) / steps) ** 2
        t, dt = 0.5 * (t0 + t1), (t1 - t0)[..., None]
        ri = np.sqrt(np.maximum(r * r + t * t + 2.0 * r * mu * t, 0.0))
        mus_i = np.minimum(np.maximum((r * mu_s + t * nu) / np.maximum(ri, 1.0), -1.0), 1.0)
        s_ray, s_mie, ext = coefficients(m, ri)
        seg = np.exp(-ext * dt)
        spread = np.where(ext > 0, (1.0 - seg) / np.where(ext > 0, ext, 1.0), dt)   # ∫ e^(−σt s) ds over dt
        lit = transmittance_to_sun(m, tlut, ri, mus_i)
        source = lit * (s_ray * phase_r[..., None] + s_mie * phase_m[..., None])
        if not isotropic and mslut is not None and m["ms"] > 0:
            u, v = ms_uv(m, ri, mus_i, mslut.shape[0])
            source = source + m["ms"] * bilinear(mslut, u, v) * (s_ray + s_mie)
        radiance += throughput * source * spread
        transfer += throughput * (s_ray + s_mie) * spread
        throughput = throughput * seg
    return radiance, transfer, throughput


def integrate(m: dict, tlut: np.ndarray, r, mu, mu_s, nu, steps: int, mslut: np.ndarray | None = None,
              isotropic: bool = False):
    """(radiance (..., 3), transfer f (..., 3)) along rays from radius ``r`` to the top or the ground:
    :func:`march` plus the sunlit ground where the ray ends on it (per unit sun irradiance when
    ``isotropic``, the multiple-scattering LUT's pass; else × the sun's illuminance). ``f`` = ∫ σs T dt,
    the multiple-scattering LUT's transfer."""
    r = clamp_radius(m, r)
    mu, mu_s, nu = (np.broadcast_to(np.asarray(a, np.float64), r.shape) for a in (mu, mu_s, nu))
    ground, t_max = ray_end(m, r, mu)
    radiance, transfer, throughput = march(m, tlut, r, mu, mu_s, nu, t_max, steps, mslut, isotropic)
    mu_g = np.clip((r * mu_s + t_max * nu) / m["rg"], -1.0, 1.0)
    lit = transmittance_to_sun(m, tlut, np.full(r.shape, m["rg"] + RADIUS_EPS), mu_g) * np.maximum(mu_g, 0.0)[..., None]
    radiance += np.where(ground[..., None], throughput * lit * m["albedo"] / math.pi, 0.0)
    return radiance * (1.0 if isotropic else m["sun"]), transfer


def aerial_perspective(settings: AtmosphereSettings, tlut, mslut, altitude: float, view_dirs, sun_dir, distance,
                       steps: int) -> tuple[np.ndarray, np.ndarray]:
    """(in-scattered radiance (..., 3), transmittance (..., 3)) over the first ``distance`` m (...,) of
    unit ``view_dirs`` (..., 3) from ``altitude``, capped at the atmosphere's end: what a surface that far
    away gets in front of it (``shaders/sky/atmosphere.glsl`` atm_aerial)."""
    m = medium(settings)
    d = np.asarray(view_dirs, np.float64)
    s = unit(sun_dir)
    r = clamp_radius(m, np.full(d.shape[:-1], camera_radius(m, altitude)))
    mu, nu = d[..., 1], d @ s
    _, end = ray_end(m, r, mu)
    radiance, _, throughput = march(m, tlut, r, mu, np.full(r.shape, s[1]), nu,
                                    np.minimum(np.asarray(distance, np.float64), end), steps, mslut)
    return radiance * m["sun"], throughput


# --- multiple scattering -----------------------------------------------------------------------------

def ms_directions(n: int = MS_DIRECTIONS) -> tuple[np.ndarray, np.ndarray]:
    """(cos zenith, cos azimuth) of n² directions evenly over the sphere (cell centres)."""
    a, b = np.meshgrid(texel_centres(n), texel_centres(n))
    return (1.0 - 2.0 * b).ravel(), np.cos(2.0 * math.pi * a).ravel()


def multiscattering_lut(settings: AtmosphereSettings, tlut: np.ndarray, size: int = MS_SIZE,
                        directions: int = MS_DIRECTIONS, steps: int = MS_STEPS) -> np.ndarray:
    """(size, size, 3) Ψms over (mu_s → u as :func:`ms_mu_s`, r → v): what multiscattering.comp makes."""
    m = medium(settings)
    x = from_sub_uv(texel_centres(size), size)          # texel i at i / (size − 1)
    mu_s = ms_mu_s(x)[None, :, None]
    r = clamp_radius(m, m["rg"] + x[:, None, None] * (m["rt"] - m["rg"]))
    mu, cos_az = ms_directions(directions)
    nu = mu * mu_s + np.sqrt(1.0 - mu * mu) * cos_az * np.sqrt(1.0 - mu_s * mu_s)
    shape = (size, size, len(mu))
    radiance, transfer = integrate(m, tlut, np.broadcast_to(r, shape), np.broadcast_to(mu, shape),
                                   np.broadcast_to(mu_s, shape), nu, steps, isotropic=True)
    l2, f = radiance.mean(axis=2), transfer.mean(axis=2)
    return l2 / (1.0 - np.minimum(f, 0.999))


# --- the sky view -------------------------------------------------------------------------------------

def camera_radius(m: dict, altitude) -> float:
    return float(clamp_radius(m, m["rg"] + max(float(altitude), 0.0)))


def sky_view_params(m: dict, r: float, u, v):
    """(view mu, cos azimuth from the sun) of sky-view LUT coordinates (u, v) seen from radius ``r``."""
    w, h = SKY_VIEW_SIZE
    xu, xv = np.clip(from_sub_uv(u, w), 0, 1), np.clip(from_sub_uv(v, h), 0, 1)
    beta = math.atan2(m["rg"], math.sqrt(max((r - m["rg"]) * (r + m["rg"]), 0.0)))
    zh = math.pi - beta
    above = xv < 0.5
    c = np.where(above, 1.0 - (1.0 - 2.0 * xv) ** 2, (2.0 * xv - 1.0) ** 2)
    theta = np.where(above, zh * c, zh + beta * c)
    return np.cos(theta), 1.0 - 2.0 * xu * xu


def sky_view_uv(m: dict, r: float, mu, cos_az):
    """The inverse of :func:`sky_view_params`."""
    w, h = SKY_VIEW_SIZE
    beta = math.atan2(m["rg"], math.sqrt(max((r - m["rg"]) * (r + m["rg"]), 0.0)))
    zh = math.pi - beta
    mu = np.clip(np.asarray(mu, np.float64), -1.0, 1.0)
    theta = 2.0 * np.arctan2(np.sqrt(np.maximum(1.0 - mu, 0.0)), np.sqrt(np.maximum(1.0 + mu, 0.0)))
    above = theta < zh
    xv = np.where(above, 0.5 * (1.0 - np.sqrt(np.maximum(1.0 - theta / zh, 0.0))),
                  0.5 + 0.5 * np.sqrt(np.maximum((theta - zh) / max(beta, 1e-9), 0.0)))
    xu = np.sqrt(np.clip(0.5 * (1.0 - np.asarray(cos_az, np.float64)), 0.0, 1.0))
    return to_sub_uv(xu, w), to_sub_uv(np.clip(xv, 0, 1), h)


def unit(v) -> np.ndarray:
    """(3,) float64 ``v`` at unit length ((0, 1, 0) for a zero or non-finite vector)."""
    a = np.asarray(v, np.float64).reshape(3)
    n = math.sqrt(a.dot(a))   # np.linalg.norm's own formula (1-D float64), without its overhead
    return a / n if math.isfinite(n) and n > 0 else np.array([0.0, 1.0, 0.0])


def view_angles(view_dirs, sun_dir) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """(view mu, cos azimuth between view and sun, sun mu_s, nu) for unit view directions (..., 3)
    and the unit sun direction (3,), y up."""
    v = np.asarray(view_dirs, np.float64)
    s = np.asarray(sun_dir, np.float64).reshape(3)
    vh = np.hypot(v[..., 0], v[..., 2])
    sh = math.hypot(s[0], s[2])
    dot = v[..., 0] * s[0] + v[..., 2] * s[2]
    cos_az = np.where((vh > 1e-9) & (sh > 1e-9), dot / np.maximum(vh * sh, 1e-300), 1.0)
    return v[..., 1], np.minimum(np.maximum(cos_az, -1.0), 1.0), float(s[1]), v @ s


def sky_view_lut(settings: AtmosphereSettings, tlut, mslut, altitude: float, sun_y: float,
                 steps: int = SKY_VIEW_STEPS) -> np.ndarray:
    """(108, 192, 3) radiance over the sky-view LUT's texels (what skyview.comp makes)."""
    m = medium(settings)
    r = camera_radius(m, altitude)
    w, h = SKY_VIEW_SIZE
    u, v = np.meshgrid(texel_centres(w), texel_centres(h))
    mu, cos_az = sky_view_params(m, r, u, v)
    mu_s = min(max(float(sun_y), -1.0), 1.0)
    nu = mu * mu_s + np.sqrt(np.maximum(1.0 - mu * mu, 0.0)) * cos_az * math.sqrt(max(1.0 - mu_s * mu_s, 0.0))
    return integrate(m, tlut, np.full(mu.shape, r), mu, mu_s, nu, steps, mslut)[0]


def sample_sky_view(settings: AtmosphereSettings, lut, altitude: float, view_dirs, sun_dir) -> np.ndarray:
    """(..., 3) the sky-view LUT read along unit ``view_dirs`` (what physical.frag reads)."""
    m = medium(settings)
    mu, cos_az, _, _ = view_angles(view_dirs, sun_dir)
    u, v = sky_view_uv(m, camera_radius(m, altitude), mu, cos_az)
    return bilinear(lut, u, v)


# --- what the CPU side needs every frame ------------------------------------------------------------

CPU_T = (128, 32)           # the CPU side's transmittance LUT (the GPU's: 256 × 64)
CPU_MS = (32, 6, 12)        # the CPU side's Ψms LUT: size, directions², steps (the GPU: 32, 8, 20)


@lru_cache(maxsize=8)
def luts(settings: AtmosphereSettings) -> tuple[np.ndarray, np.ndarray]:
    """(transmittance, multiple scattering) LUTs of ``settings`` in float64 for the CPU side
    (:func:`sky_radiance`, :func:`sun_radiance`, :func:`ambient`), made once per settings; the
    both coarser than the GPU's (``CPU_T``, ``CPU_MS``: ~4× cheaper to make)."""
    tlut = transmittance_lut(settings, size=CPU_T)
    size, directions, steps = CPU_MS
    return tlut, multiscattering_lut(settings, tlut, size, directions, steps)


def sky_radiance(view_dirs, sun_dir, altitude: float = 0.0, settings: AtmosphereSettings | None = None,
                 steps: int = SKY_VIEW_STEPS) -> np.ndarray:
    """(..., 3) the sky's radiance (single + multiple scattering; the sunlit ground below the
    horizon) along unit ``view_dirs`` from ``altitude`` m for the unit ``sun_dir``, ray-marched directly."""
    settings = settings or AtmosphereSettings()
    tlut, mslut = luts(settings)
    m = medium(settings)
    mu, _, mu_s, nu = view_angles(view_dirs, sun_dir)
    r = np.full(np.shape(mu), camera_radius(m, altitude))
    return integrate(m, tlut, r, mu, mu_s, nu, steps, mslut)[0]


def sun_radiance(sun_dir, altitude=0.0, settings: AtmosphereSettings | None = None) -> np.ndarray:
    """(..., 3) the sun's colour at ``altitude`` (m, a number or an array): ``sun_color`` × the
    transmittance toward it (``SUN_STEPS`` midpoint steps) × the share of its disc above the horizon
    (what ``Sun.color`` becomes with the physical sky)."""
    settings = settings or AtmosphereSettings()
    m = medium(settings)
    mu_s = float(unit(sun_dir)[1])
    r = clamp_radius(m, m["rg"] + np.maximum(np.asarray(altitude, np.float64), 0.0))
    mu = np.maximum(mu_s, horizon_mu(m["rg"], r))
    depth = optical_depth(m, r, mu, distance_to_top(m["rt"], r, mu), SUN_STEPS)
    return m["color"] * np.exp(-depth) * sun_visibility(m["rg"], r, mu_s)[..., None]


SUN_STEPS = 256              # the sun's colour: its one ray integrated directly (no LUT)
AMBIENT_ZENITH, AMBIENT_AZIMUTH = 8, 8       # Gauss–Legendre nodes in mu over the upper hemisphere × azimuths over 0..π
AMBIENT_STEPS = 16                           # steps per ray (the hemisphere's integral is smooth)


def ambient(sun_dir, altitude: float = 0.0, settings: AtmosphereSettings | None = None) -> np.ndarray:
    """(3,) the sky's irradiance on an upward surface / π (the cosine-weighted mean radiance of the
    upper hemisphere, what ``Sun.ambient`` becomes): Gauss–Legendre in mu × the midpoint rule in
    azimuth (the sky is symmetric about the sun's vertical plane)."""
    x, w = np.polynomial.legendre.leggauss(AMBIENT_ZENITH)
    mu, wmu = 0.5 * (x + 1.0), 0.5 * w
    phi = (np.arange(AMBIENT_AZIMUTH) + 0.5) / AMBIENT_AZIMUTH * math.pi
    s = np.asarray(sun_dir, np.float64).reshape(3)
    sh = math.hypot(s[0], s[2])
    ax, az = (s[0] / sh, s[2] / sh) if sh > 1e-9 else (1.0, 0.0)
    sin_t, up = np.sqrt(1.0 - mu * mu)[:, None], mu[:, None]
    c, d = np.cos(phi)[None, :], np.sin(phi)[None, :]
    dirs = np.stack([sin_t * (c * ax - d * az), np.broadcast_to(up, (len(mu), len(phi))),
                     sin_t * (c * az + d * ax)], axis=-1)
    rad = sky_radiance(dirs, s, altitude, settings, AMBIENT_STEPS)
    # E / π = (1/π) ∫∫ L mu dmu dφ over φ in 0..2π = (2/π) ∫ mu ∫_0^π L dφ dmu
    return (2.0 / math.pi) * np.einsum("i,ijc->c", wmu * mu, rad) * (math.pi / AMBIENT_AZIMUTH)
