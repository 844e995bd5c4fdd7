"""Phase functions in float64 (1/sr): the reference of ``shaders/lib/phase.glsl``, which the clouds'
light model and the light shafts' haze both scatter with."""
from __future__ import annotations

import math

import numpy as np


def hg(cos, g):
    """One Henyey-Greenstein lobe (1/sr)."""
    return (1.0 - g * g) / (4.0 * math.pi * np.maximum(1.0 + g * g - 2.0 * g * np.asarray(cos), 1e-12) ** 1.5)


def phase(cos, g: float, g2: float, w: float):
    """The two-lobe phase function (1/sr) at the cosine of the scattering angle."""
    return (1.0 - w) * hg(cos, g) + w * hg(cos, g2)
