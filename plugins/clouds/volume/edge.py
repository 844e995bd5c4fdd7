"""The cloud volume's radial edge fade (``shaders/clouds/volume/edge.glsl``), float64.

The simulated volume is a square around the camera; drawn as it is, its edge shows as a straight
line (a V in an overcast deck, straight shadow edges). ``CloudSettings.edge_fade`` fades its
density to 0 toward the inscribed circle: at footprint position ``uv`` (0..1 across the volume),
``r = |2 uv − 1|`` and ``weight = 1 − smoothstep(1 − fade, 1, r)``; ``fade`` 0 keeps the square.
Sprites, the ray march and the ground shadows multiply density by it; the far field
(:mod:`atmos.plugins.clouds.far_field`) draws with ``1 − weight`` over the same band, so there is no seam.
"""
from __future__ import annotations

import numpy as np

from atmos.glsl_math import smoothstep
from atmos.plugins.clouds.volume.layout import CloudLayout


def edge_weight(uv, fade: float) -> np.ndarray:
    """The weight (...,) at footprint positions ``uv`` (..., 2)."""
    uv = np.asarray(uv, np.float64)
    if fade <= 0.0:
        return np.ones(uv.shape[:-1])
    r = np.linalg.norm(2.0 * uv - 1.0, axis=-1)
    return 1.0 - smoothstep(1.0 - fade, 1.0, r)


def footprint_uv(layout: CloudLayout, xz) -> np.ndarray:
    """Footprint positions (..., 2) of world points ``xz`` (..., 2) in ``layout``."""
    lo, hi = layout.lo[[0, 2]], layout.hi[[0, 2]]
    return (np.asarray(xz, np.float64) - lo) / (hi - lo)
