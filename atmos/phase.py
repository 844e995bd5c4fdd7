"""Phase functions in float64 (1/sr): the reference of ``shaders/lib/phase.glsl``, which the clouds'
light model and the light shafts' haze both scatter with, and :class:`Phase`, the two-lobe shape
their settings hold."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, num_field


def hg(cos, g):
    """One Henyey-Greenstein lobe (1/sr)."""
    return (1.0 - g * g) / (4.0 * math.pi * np.maximum(1.0 + g * g - 2.0 * g * np.asarray(cos), 1e-12) ** 1.5)


def phase(cos, g: float, g2: float, w: float):
    """The two-lobe phase function (1/sr) at the cosine of the scattering angle."""
    return (1.0 - w) * hg(cos, g) + w * hg(cos, g2)


@dataclass(frozen=True)
class Phase(CheckedSettings):
    """Two Henyey-Greenstein lobes, ``(1 - w) HG(g) + w HG(g2)``: a forward lobe and a weaker
    backward one (``lobes`` is what ``shaders/lib/phase.glsl`` takes)."""

    g: float = num_field(0.85, -0.99, 0.99, "the first lobe's asymmetry (> 0: forward)")
    g2: float = num_field(-0.3, -0.99, 0.99, "the second lobe's asymmetry (< 0: backward)")
    w: float = num_field(0.1, 0.0, 1.0, "the second lobe's weight")

    def __call__(self, cos):
        """The phase function (1/sr) at the cosine of the scattering angle."""
        return phase(cos, self.g, self.g2, self.w)

    @property
    def lobes(self) -> tuple[float, float, float]:
        """(g, g2, w) as floats: the GLSL uniform ``vec3 lobes``."""
        return float(self.g), float(self.g2), float(self.w)

    @property
    def mean_cosine(self) -> float:
        """The mean cosine of the scattering angle, ``(1 - w) g + w g2``."""
        return (1.0 - self.w) * self.g + self.w * self.g2

    @property
    def hemisphere_share(self) -> float:
        """The share of the light scattered into a direction d that came from the hemisphere about d:
        per lobe (1 - g²) / 2g (1 / (1 - g) - 1 / sqrt(1 + g²)) (1/2 at g = 0)."""
        def lobe(g):
            return 0.5 + 0.375 * g if abs(g) < 1e-4 else (1 - g * g) / (2 * g) * (1 / (1 - g) - 1 / math.sqrt(1 + g * g))
        return (1.0 - self.w) * lobe(self.g) + self.w * lobe(self.g2)
