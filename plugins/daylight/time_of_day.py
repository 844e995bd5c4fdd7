"""Solar position from a time of day, and the plugin that turns it into the Sun resource."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, check_num
from atmos.lighting import Sun, sky_light
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


@dataclass(frozen=True)
class DaylightSettings(CheckedSettings):
    """``hours``: local solar time in [0, 24] the clock starts at (``configure(hours=...)`` sets the
    clock to it); ``speed``: in-game hours per real second (0 stops the clock); ``latitude`` in
    degrees (−90..90); ``day_of_year`` 1..366. All live (next frame)."""
    hours: float = 10.0
    speed: float = 0.0
    latitude: float = 45.0
    day_of_year: float = 172.0

    def __post_init__(self):
        o = "DaylightSettings"
        self.store(dict(hours=check_num(o, "hours", self.hours, 0.0, 24.0),
                        speed=check_num(o, "speed", self.speed),
                        latitude=check_num(o, "latitude", self.latitude, -90.0, 90.0),
                        day_of_year=check_num(o, "day_of_year", self.day_of_year, 1.0, 366.0)))


@dataclass(slots=True)
class TimeOfDay:
    """The running clock (a resource the daylight system advances every frame): ``hours``, local
    solar time in [0, 24)."""
    hours: float = 10.0


class DaylightPlugin(Plugin):
    """The day–night cycle: ``DaylightPlugin(settings=None, **fields)`` with :class:`DaylightSettings`;
    a TimeOfDay resource driving the Sun resource (update stage, "daylight").
    ``configure(**changes)`` changes any setting live; ``hours`` also sets the clock."""

    settings_class = DaylightSettings

    def __init__(self, settings: DaylightSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.time_of_day = TimeOfDay(self.settings.hours)

    def configure(self, **changes) -> DaylightSettings:
        settings = super().configure(**changes)
        if "hours" in changes:
            self.time_of_day.hours = settings.hours % 24.0
        return settings

    def sun_direction(self) -> np.ndarray:
        """Unit vector toward the sun at the clock's time."""
        s = self.settings
        return solar_direction(self.time_of_day.hours, s.latitude, s.day_of_year)

    def advance(self, app) -> None:
        """System: advance the clock by ``speed × dt`` and write the Sun's direction, colour and ambient."""
        tod = self.time_of_day
        tod.hours = (tod.hours + self.settings.speed * app.clock.dt) % 24.0
        sun = app.get_resource(Sun)
        if sun is None:
            sun = Sun()
            app.insert_resource(sun)
        sun.direction = self.sun_direction()
        color, ambient = sky_light(sun.direction)
        sun.color, sun.ambient = tuple(color), tuple(ambient)

    def build(self, app) -> None:
        app.insert_resource(self.time_of_day)
        self.advance(app)        # the Sun is right from the start, whatever runs first at start-up
        app.add_system(self.advance, "update", label="daylight")
        app.add_system(self.advance, "startup", label="daylight_start")
