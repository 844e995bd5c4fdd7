"""The sun as a resource: where it is and what colour its light has."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(slots=True)
class Sun:
    """``direction`` points from the scene toward the sun (unit length); ``color`` is its radiance
    (zero at night); ``ambient`` is the sky's diffuse light. DaylightPlugin drives all three."""
    direction: np.ndarray = field(default_factory=lambda: np.array([0.3, 0.35, -0.88]))
    color: tuple = (1.0, 0.95, 0.85)
    ambient: tuple = (0.35, 0.47, 0.65)

    @classmethod
    def from_angles(cls, elevation_deg: float, azimuth_deg: float = 0.0, color=(1.0, 0.95, 0.85)) -> "Sun":
        e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
        return cls(np.array([math.sin(a) * math.cos(e), math.sin(e), -math.cos(a) * math.cos(e)]), color)
