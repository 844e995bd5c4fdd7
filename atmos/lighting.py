"""The sun as a resource: where it is and what colour its light has."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from atmos.camera import Camera, set_camera_uniforms


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


def sun_and_day(sun: Sun) -> tuple[np.ndarray, float]:
    """(unit direction toward the sun, daylight 0..1 = smoothstep(-0.15, 0.1, sun height) like the sky)."""
    s = np.asarray(sun.direction, np.float64)
    norm = np.linalg.norm(s)
    s = s / norm if np.isfinite(norm) and norm > 1e-9 else np.array([0.0, 1.0, 0.0])
    day = float(np.clip((s[1] + 0.15) / 0.25, 0.0, 1.0))
    return s, day * day * (3 - 2 * day)


def scene_sun(app) -> Sun:
    """The App's Sun resource, or the default sun for a scene that has none."""
    return app.get_resource(Sun) or _DEFAULT_SUN


def set_sun_uniforms(program, sun: Sun) -> None:
    """Write ``sun_dir`` and ``sun_color`` where the program has them."""
    for name, value in (("sun_dir", sun.direction), ("sun_color", sun.color)):
        if name in program:
            program[name].value = tuple(float(v) for v in value)


def set_scene_uniforms(program, app, aspect: float) -> None:
    """The App's camera (:func:`atmos.camera.set_camera_uniforms`) and sun (:func:`set_sun_uniforms`)
    uniforms: what a pass drawing the lit scene writes each frame."""
    set_camera_uniforms(program, app.resource(Camera), aspect)
    set_sun_uniforms(program, scene_sun(app))


_DEFAULT_SUN = Sun()
