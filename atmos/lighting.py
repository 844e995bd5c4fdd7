"""The sun as a resource: where it is and what colour its light has; the sun/sky light model.

:func:`sky_light` gives the sun's colour (reddened near the horizon, zero at night) and the sky's
ambient colour for a sun direction: what DaylightPlugin writes into :class:`Sun`, and what the sky
(``NIGHT_SKY``) and the cloud light (:mod:`atmos.plugins.clouds.light.scattering`) build on.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from atmos.checks import check_sun_dir, check_vec

RAYLEIGH = np.array([0.03, 0.07, 0.16])      # extinction of sunlight per air mass (red, green, blue)
DAY_SKY = np.array([0.35, 0.47, 0.65])
TWILIGHT_SKY = np.array([0.30, 0.22, 0.25])
NIGHT_SKY = np.array([0.012, 0.016, 0.03])


def _read_only(direction: np.ndarray) -> np.ndarray:
    direction.setflags(write=False)        # changed by assigning a new one (checked), never in place
    return direction


def _check_path(value):
    if value is not None and not callable(value):
        raise ValueError("Sun.color_by_altitude must be None or a callable (direction, altitudes_m (n,)) -> RGB (n, 3), "
                         f"got {value!r}")
    return value


_SUN_CHECKS = {
    "direction": lambda v: _read_only(check_sun_dir(v, "Sun.direction")),
    "color": lambda v: check_vec("Sun", "color", v, 3, "non-negative"),
    "ambient": lambda v: check_vec("Sun", "ambient", v, 3, "non-negative"),
    "color_by_altitude": _check_path,
}


class GroundSurface:
    """The scene's ground as light sees it: ``albedo``, the linear RGB reflectance of what the terrain or
    ground plane draws (each in [0, 1]), given as a tuple or as a callable read each frame (a live change
    of the drawing plugin's settings is seen on the next one). TerrainPlugin and GroundPlugin insert one;
    the clouds' light from below takes it (:mod:`atmos.plugins.clouds.light.medium`)."""

    __slots__ = ("_albedo",)

    def __init__(self, albedo=(0.3, 0.3, 0.3)):
        if not callable(albedo):
            albedo = check_vec("GroundSurface", "albedo", albedo, 3, "non-negative")
            if max(albedo) > 1.0:
                raise ValueError(f"GroundSurface.albedo must be 3 numbers in [0, 1], got {albedo!r}")
        self._albedo = albedo

    @property
    def albedo(self) -> tuple:
        a = self._albedo
        return tuple(float(min(max(c, 0.0), 1.0)) for c in (a() if callable(a) else a))


@dataclass(slots=True)
class Sun:
    """``direction`` points from the scene toward the sun (kept at unit length, read-only: assign a
    new one); ``color`` is its radiance (zero at night); ``ambient`` is the sky's diffuse light (linear
    RGB, non-negative). Every assignment is checked (a ValueError names ``Sun.field``). DaylightPlugin
    drives all three. ``color`` is the sun seen from the camera; ``color_by_altitude`` (set by a sky
    model that knows the air's path, the physical sky; None: ``color`` everywhere) gives it at other
    altitudes, through :meth:`color_at`: clouds 2 km up see a less reddened sun, and still see it after
    the ground's sunset. It is called as ``color_by_altitude(direction, altitudes)`` with an (n,) array
    and returns (n, 3) (numpy-vectorised: a cloud layer asks for its heights at once)."""
    direction: np.ndarray = field(default_factory=lambda: np.array([0.3, 0.35, -0.88]))
    color: tuple = (1.0, 0.95, 0.85)
    ambient: tuple = (0.35, 0.47, 0.65)
    color_by_altitude: object = None

    def color_at(self, altitude) -> np.ndarray:
        """(3,) the sun's colour at ``altitude`` m, or (n, 3) at an (n,) array of altitudes:
        ``color_by_altitude(direction, altitudes)``, or ``color`` without one."""
        heights = np.asarray(altitude, np.float64)
        if self.color_by_altitude is None:
            return np.broadcast_to(np.asarray(self.color, np.float64), heights.shape + (3,)).copy()
        flat = heights.reshape(-1)
        color = np.asarray(self.color_by_altitude(self.direction, flat), np.float64)
        if color.shape != (len(flat), 3) or not np.all(np.isfinite(color)) or color.min() < 0:
            raise ValueError(f"Sun.color_by_altitude must return ({len(flat)}, 3) non-negative finite numbers "
                             f"for {len(flat)} altitudes, got {color!r}")
        return color.reshape(heights.shape + (3,))

    def __setattr__(self, name: str, value) -> None:
        check = _SUN_CHECKS.get(name)
        object.__setattr__(self, name, check(value) if check is not None else value)

    @classmethod
    def from_angles(cls, elevation_deg: float, azimuth_deg: float = 0.0, color=(1.0, 0.95, 0.85)) -> "Sun":
        e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
        return cls(np.array([math.sin(a) * math.cos(e), math.sin(e), -math.cos(a) * math.cos(e)]), color)


def unit_sun(direction) -> np.ndarray | None:
    """The unit direction toward the sun, or None when it is not a finite non-zero vector."""
    s = np.asarray(direction, np.float64).reshape(3)
    norm = math.sqrt(s.dot(s))           # np.linalg.norm's own formula, without its overhead
    return s / norm if math.isfinite(norm) and norm > 1e-12 else None


def _smoothstep(e0: float, e1: float, x: float) -> float:
    t = min(max((x - e0) / (e1 - e0), 0.0), 1.0)
    return t * t * (3 - 2 * t)


def sky_light(sun_dir, ambient_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(sun colour, ambient colour) as float64 RGB for a sun in direction ``sun_dir`` (y up).

    Sun: reddened by ``exp(-RAYLEIGH * air mass)`` (Kasten-Young air mass), faded out across the
    horizon over the sun disc (-0.5 deg .. 0.5 deg), 0 below. Ambient: day blue, tinted at twilight,
    dark blue at night (``NIGHT_SKY``), scaled by ``ambient_scale`` (a cloud
    :class:`~atmos.plugins.clouds.light.Scattering`'s ``ambient``). Continuous in the direction.
    """
    u = check_sun_dir(sun_dir)
    e = math.degrees(math.asin(max(-1.0, min(1.0, u[1]))))
    height = max(e, 0.0)
    air_mass = 1.0 / (math.sin(math.radians(height)) + 0.50572 * (height + 6.07995) ** -1.6364)
    sun = np.exp(-RAYLEIGH * air_mass) * _smoothstep(-0.5, 0.5, e)
    day = _smoothstep(-6.0, 20.0, e)
    twilight = _smoothstep(-8.0, 0.0, e) * (1.0 - _smoothstep(0.0, 15.0, e))
    ambient = NIGHT_SKY + day * DAY_SKY + 0.5 * twilight * TWILIGHT_SKY
    return sun, ambient * float(ambient_scale)


def sun_and_day(sun: Sun) -> tuple[np.ndarray, float]:
    """(unit direction toward the sun, daylight 0..1 = smoothstep(-0.15, 0.1, sun height) like the sky)."""
    s = unit_sun(sun.direction)
    if s is None:
        s = np.array([0.0, 1.0, 0.0])
    day = float(np.clip((s[1] + 0.15) / 0.25, 0.0, 1.0))
    return s, day * day * (3 - 2 * day)
