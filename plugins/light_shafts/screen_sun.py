"""Where the sun is on the screen, and how strongly the shafts show (both computed once per frame)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from atmos.camera import camera_matrices
from atmos.lighting import unit_sun

UV_LIMIT = 64.0     # a sun further off-screen is faded out; its uv is clamped to keep the blur finite


def _smoothstep(e0: float, e1: float, x: float) -> float:
    t = min(max((x - e0) / (e1 - e0), 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


@dataclass(frozen=True)
class ScreenSun:
    """``uv``: the sun's position in [0, 1]² screen coordinates (y up; outside when off-screen);
    ``strength``: the product of the fades, 0 when the shafts are not drawn at all."""
    uv: tuple
    strength: float


def screen_sun(camera, aspect: float, sun_direction, settings) -> ScreenSun:
    """Project the direction toward the sun (a point at infinity) with ``camera``'s view-projection."""
    s = unit_sun(sun_direction)
    if s is None:
        return ScreenSun((0.5, 0.5), 0.0)
    matrices = camera_matrices(camera, aspect)
    facing = float(np.dot(-matrices.view[2, :3], s))          # the camera's forward
    strength = _smoothstep(0.0, settings.horizon_fade, s[1]) * _smoothstep(0.0, settings.front_fade, facing)
    if strength <= 0.0:
        return ScreenSun((0.5, 0.5), 0.0)
    clip = matrices.view_proj[:, :3] @ s                     # (s, 0): a point at infinity
    u, v = (min(max(float(0.5 * c / clip[3] + 0.5), -UV_LIMIT), UV_LIMIT) for c in clip[:2])
    outside = max(-u, u - 1.0, -v, v - 1.0, 0.0)
    strength *= 1.0 - _smoothstep(0.0, settings.edge_fade, outside)
    return ScreenSun((u, v), strength)
