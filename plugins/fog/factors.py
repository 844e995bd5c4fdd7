"""float64 references of the fog factor (Zdrojewska eq. 2-4, 6, 7) and the blend of eq. (1).

Safe at every extreme, like ``shaders/fog/factor.glsl``: d is clamped to [0, 3e38] (so +inf never
meets 0), a zero medium (g * turbulence <= 0) gives f = 1, the optical depth is capped at 1e4, and
f is clipped to [0, 1].
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.fog.settings import HETEROGENEOUS, MODES

MAX_DISTANCE = 3e38
MAX_DEPTH = 1e4


def height_depth(distance, g, eye_y, slope, base: float, scale: float) -> np.ndarray:
    """Optical depth of height fog (density g e^(-(y - base)/scale)) along a ray from height ``eye_y``
    climbing ``slope`` m per m, over ``distance``: g e^(-(y_low - base)/scale) d (1 - e^(-a)) / a with
    a = |Δy| / scale, in logs (fog/factor.glsl), capped at MAX_DEPTH."""
    d = np.asarray(distance, np.float64)
    a = np.abs(np.asarray(slope, np.float64) * d) / scale
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        mean = np.where(a < 1e-8, 1.0 - 0.5 * a, -np.expm1(-a) / np.where(a > 0, a, 1.0))
        low = np.minimum(eye_y, eye_y + np.asarray(slope, np.float64) * d)
        log_tau = np.log(g) - (low - base) / scale + np.log(np.maximum(d * mean, 1e-300))
    return np.where(d * mean > 0, np.exp(np.minimum(log_tau, np.log(MAX_DEPTH))), 0.0)   # no path: no fog


def fog_factor(mode: str, distance, density: float = 0.0, start: float = 0.0, end: float = 1.0,
               turbulence=1.0, eye_y=0.0, slope=0.0, base: float = 0.0, scale: float = 50.0) -> np.ndarray:
    """f in [0, 1] (1: no fog). ``turbulence`` scales g in the heterogeneous modes (eq. 6, 7); the
    height modes take the ray's ``eye_y``, ``slope`` (dy per metre) and the fog's ``base`` and ``scale``
    height (:func:`height_depth`)."""
    d = np.clip(np.asarray(distance, np.float64), 0.0, MAX_DISTANCE)
    if MODES[mode] == 0:
        return np.clip((end - d) / (end - start), 0.0, 1.0)                        # eq. (2)
    g = np.float64(density) * (np.asarray(turbulence, np.float64) if mode in HETEROGENEOUS else 1.0)
    g = np.broadcast_to(g, d.shape)
    if mode in ("height", "hetero_height"):
        x = np.where(g > 0, height_depth(d, np.where(g > 0, g, 1.0), eye_y, slope, base, scale), 0.0)
        return np.where(g > 0, np.clip(np.exp(-x), 0.0, 1.0), 1.0)
    with np.errstate(over="ignore"):
        x = np.minimum(d * g, MAX_DEPTH)
    if mode in ("exp2", "hetero_exp2"):
        x = x * x                                                                   # eq. (4), (7)
    return np.where(g > 0, np.clip(np.exp(-x), 0.0, 1.0), 1.0)                      # eq. (3), (6)


def blend(color, fog_color, f) -> np.ndarray:
    """Eq. (1): C = f C_current + (1 - f) C_fog, float64 (H, W, 3)."""
    f = np.asarray(f, np.float64)[..., None]
    return f * np.asarray(color, np.float64) + (1.0 - f) * np.asarray(fog_color, np.float64)


def apply_fog_ref(color, distance, settings, positions=None, time: float = 0.0, far: float = np.inf,
                  volumes=None, cloud=None, directions=None, camera=(0.0, 0.0, 0.0), horizon=None,
                  ground: bool = False, sun=None) -> np.ndarray:
    """float64 reference of :func:`atmos.plugins.fog.apply_fog` (``settings`` validated FogSettings).

    Sky pixels (distance +inf) use ``far`` or stay as they are when ``settings.sky == "keep"``.
    ``volumes`` as in :func:`atmos.plugins.fog.noise.turbulence_ref` (None: procedural). ``cloud``
    (H, W, 2) premultiplied (a·d, a) (:mod:`atmos.composition`): f = a f(d) + (1 − a) f(behind), the
    cloud's noise at ``camera + directions × d``; ``horizon``: ``color_from="sky"``'s table.
    ``ground`` (the fog pass from depth, ``fog/fog.frag``): with ``sky="keep"``, sky below the horizon
    seen from above y = 0 is fogged as that plane at ``camera.y / −direction.y``.
    """
    from atmos.plugins.fog.noise import turbulence_ref
    from atmos.plugins.fog.sky_color import ZENITH, sky_fog_color

    eye = np.asarray(camera, np.float64)

    def factor(d, where):
        turbulence = turbulence_ref(where, time, settings, volumes) if settings.heterogeneous else 1.0
        toward = np.asarray(where, np.float64) - eye
        slope = toward[..., 1] / np.maximum(np.linalg.norm(toward, axis=-1), 1e-30)     # as fog/factor.glsl
        return fog_factor(settings.mode, d, settings.density, settings.start, settings.end, turbulence,
                          eye[1], slope, settings.height_base, settings.scale_height)

    d = np.asarray(distance, np.float64)
    sky = np.isinf(d)
    d = np.where(sky, far, d)
    if ground and settings.sky == "keep" and camera[1] > 0.0:
        down = np.asarray(directions, np.float64)[..., 1]
        below = sky & (down < 0.0)
        d = np.where(below, camera[1] / np.maximum(-down, 1e-6), d)
        positions = np.where(below[..., None], np.asarray(camera, np.float64) + np.asarray(directions) * d[..., None],
                             positions)
        sky = sky & ~below
    f = factor(d, positions)
    if settings.sky == "keep":
        f = np.where(sky, 1.0, f)
    if cloud is not None:
        cloud = np.asarray(cloud, np.float64)
        a = np.clip(cloud[..., 1], 0.0, 1.0)
        dc = np.maximum(cloud[..., 0] / np.where(a > 0, cloud[..., 1], 1.0), 0.0)
        where = np.asarray(camera, np.float64) + np.asarray(directions, np.float64) * dc[..., None]
        f = np.where(a > 0, a * factor(dc, where) + (1.0 - a) * f, f)
    sky_sun = ZENITH if sun is None else sun.direction
    fog = (settings.fog_color if settings.color_from == "fixed"
           else sky_fog_color(directions, horizon, settings.fog_color, sky_sun))
    if sun is not None and settings.sun_scattering > 0:
        fog = fog + fog_light(directions, sun, settings)
    return blend(color, fog, f)


def fog_light(directions, sun, settings) -> np.ndarray:
    """(..., 3) sunlight the fog scatters along unit ``directions``: Sun.color × sun_scattering × daylight
    × 4π p(θ) with ``settings.phase`` (fog/color.glsl sun_in)."""
    from atmos.lighting import sun_and_day
    direction, day = sun_and_day(sun)
    light = np.asarray(sun.color, np.float64) * settings.sun_scattering * day
    cos = np.asarray(directions, np.float64) @ np.asarray(direction, np.float64)
    return light * (4.0 * np.pi * settings.phase(cos))[..., None]
