"""Solar position from a time of day, and the plugin that turns it into the Sun resource."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.lighting import Sun
from atmos.plugin import Plugin


def solar_direction(hours: float, latitude: float = 45.0, day_of_year: float = 172.0) -> np.ndarray:
    """Unit vector toward the sun (x east, y up, −z north) at local solar time ``hours``.

    Declination δ = −23.44° cos(2π (day + 10) / 365); hour angle h = 15° (hours − 12);
    elevation from sin e = sin φ sin δ + cos φ cos δ cos h (φ the latitude). Below the horizon the
    vector points below it (y < 0): night.
    """
    phi = math.radians(latitude)
    delta = math.radians(-23.44 * math.cos(2 * math.pi * (day_of_year + 10) / 365.0))
    h = math.radians(15.0 * (hours - 12.0))
    # the sun in the local east-north-up frame: rotate the equatorial direction by the latitude
    east = -math.cos(delta) * math.sin(h)
    north = math.sin(delta) * math.cos(phi) - math.cos(delta) * math.cos(h) * math.sin(phi)
    up = math.sin(delta) * math.sin(phi) + math.cos(delta) * math.cos(h) * math.cos(phi)
    v = np.array([east, up, -north])
    return v / np.linalg.norm(v)


@dataclass
class TimeOfDay:
    """``hours``: local solar time in [0, 24); ``speed``: in-game hours per real second (0 stops
    the clock); ``latitude`` in degrees (−90..90); ``day_of_year`` 1..365."""
    hours: float = 10.0
    speed: float = 0.0
    latitude: float = 45.0
    day_of_year: float = 172.0

    def validate(self) -> "TimeOfDay":
        for name, lo, hi in (("hours", 0.0, 24.0), ("latitude", -90.0, 90.0), ("day_of_year", 1.0, 366.0)):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise ValueError(f"TimeOfDay.{name} must be a number in [{lo}, {hi}], got {value!r}")
        if not (isinstance(self.speed, (int, float)) and math.isfinite(self.speed)):
            raise ValueError(f"TimeOfDay.speed must be a finite number of in-game hours per second, got {self.speed!r}")
        return self

    @property
    def sun_direction(self) -> np.ndarray:
        return solar_direction(self.hours, self.latitude, self.day_of_year)


def advance_daylight(app) -> None:
    """System: advance the clock by ``speed × dt`` and write the Sun's direction, colour and ambient."""
    from atmos.plugins.shading.scattering import sky_light
    tod: TimeOfDay = app.resource(TimeOfDay)
    tod.hours = (tod.hours + tod.speed * app.clock.dt) % 24.0
    sun = app.get_resource(Sun)
    if sun is None:
        sun = Sun()
        app.insert_resource(sun)
    sun.direction = tod.sun_direction
    color, ambient = sky_light(sun.direction)
    sun.color, sun.ambient = tuple(color), tuple(ambient)


class DaylightPlugin(Plugin):
    """The day–night cycle: a TimeOfDay resource driving the Sun resource (update stage, "daylight")."""

    def __init__(self, time_of_day: TimeOfDay | None = None, **fields):
        self.time_of_day = (time_of_day or TimeOfDay(**fields)).validate()

    def build(self, app) -> None:
        app.insert_resource(self.time_of_day)
        app.add_system(advance_daylight, "update", label="daylight")
        app.add_system(advance_daylight, "startup", label="daylight_start")
