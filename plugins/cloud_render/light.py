"""The light model both cloud renderers share: colour = sun colour × transmittance + ambient."""
from __future__ import annotations

import numpy as np

from atmos.lighting import Sun

DEFAULT_AMBIENT = (0.35, 0.47, 0.65)


def sun_light(sun: Sun | None) -> tuple[tuple, tuple]:
    """(sun colour, ambient) as float tuples; the sun colour fades to 0 across the horizon
    (direction y from −0.01 to 0.01), so a sun below it leaves ambient light only."""
    sun = sun or Sun()
    direction = np.asarray(sun.direction, np.float64)
    norm = np.linalg.norm(direction)
    y = direction[1] / norm if norm > 0 and np.isfinite(norm) else -1.0
    x = min(max((y + 0.01) / 0.02, 0.0), 1.0)
    fade = x * x * (3.0 - 2.0 * x)
    color = tuple(float(c) * fade for c in sun.color)
    ambient = tuple(float(c) for c in getattr(sun, "ambient", DEFAULT_AMBIENT))
    return color, ambient
