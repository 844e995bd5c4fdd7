"""float64 references of the fog factor (Zdrojewska eq. 2-4, 6, 7) and the blend of eq. (1).

Safe at every extreme, like ``shaders/fog/factor.glsl``: d is clamped to [0, 3e38] (so +inf never
meets 0), a zero medium (g * turbulence <= 0) gives f = 1, the optical depth is capped at 1e4, and
f is clipped to [0, 1].
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.fog.settings import MODES

MAX_DISTANCE = 3e38
MAX_DEPTH = 1e4


def fog_factor(mode: str, distance, density: float = 0.0, start: float = 0.0, end: float = 1.0,
               turbulence=1.0) -> np.ndarray:
    """f in [0, 1] (1: no fog). ``turbulence`` scales g in the heterogeneous modes (eq. 6, 7)."""
    d = np.clip(np.asarray(distance, np.float64), 0.0, MAX_DISTANCE)
    if MODES[mode] == 0:
        return np.clip((end - d) / (end - start), 0.0, 1.0)                        # eq. (2)
    g = np.float64(density) * (np.asarray(turbulence, np.float64) if MODES[mode] >= 3 else 1.0)
    g = np.broadcast_to(g, d.shape)
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
                  volumes=None) -> np.ndarray:
    """float64 reference of :func:`atmos.plugins.fog.apply_fog` (``settings`` validated FogSettings).

    Sky pixels (distance +inf) use ``far`` or stay as they are when ``settings.sky == "keep"``.
    ``volumes`` as in :func:`atmos.plugins.fog.noise.turbulence_ref` (None: procedural).
    """
    from atmos.plugins.fog.noise import turbulence_ref

    d = np.asarray(distance, np.float64)
    sky = np.isinf(d)
    d = np.where(sky, far, d)
    turbulence = 1.0
    if settings.heterogeneous:
        turbulence = turbulence_ref(positions, time, settings, volumes)
    f = fog_factor(settings.mode, d, settings.density, settings.start, settings.end, turbulence)
    if settings.sky == "keep":
        f = np.where(sky, 1.0, f)
    return blend(color, settings.fog_color, f)
