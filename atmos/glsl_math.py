"""float64 twins of the GLSL built-ins the references share (numpy, any shape)."""
from __future__ import annotations

import numpy as np


def smoothstep(e0: float, e1: float, x) -> np.ndarray:
    """GLSL's smoothstep: 0 below ``e0``, 1 above ``e1``, 3t² − 2t³ between (``e0 > e1`` runs backward)."""
    t = np.minimum(np.maximum((np.asarray(x, np.float64) - e0) / (e1 - e0), 0.0), 1.0)   # a clip in ufuncs (no Python wrapper)
    return t * t * (3.0 - 2.0 * t)


def catmull_rom_weights(t) -> tuple:
    """Catmull-Rom weights of the taps at -1, 0, 1, 2 for fractions ``t`` (``shaders/lib/catmull_rom.glsl``)."""
    t = np.asarray(t, np.float64)
    return (t * (-0.5 + t * (1.0 - 0.5 * t)), 1.0 + t * t * (-2.5 + 1.5 * t), t * (0.5 + t * (2.0 - 1.5 * t)),
            t * t * (-0.5 + 0.5 * t))
