"""The plugin that turns a time of day into the Sun resource (the position: :mod:`.solar_position`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, check_num, int_field, num_field
from atmos.lighting import Sun, sky_light
from atmos.plugin import Plugin
from atmos.plugins.daylight.solar_position import solar_direction


@dataclass(frozen=True)
class DaylightSettings(CheckedSettings):
    """The clock and the place that set the sun's direction: positions within ~0.01° of NREL's SPA
    (:mod:`atmos.plugins.daylight.solar_position`). All live (next frame)."""
    hours: float = num_field(10.0, 0.0, 24.0, "the time of day the clock starts at (configure(hours=...) sets "
                             "the clock to it): local apparent solar time (12 = the sun due south or north), "
                             "or, once a longitude is given, clock time in the zone utc_offset hours from UTC")
    speed: float = num_field(0.0, doc="in-game hours per real second (0 stops the clock)")
    latitude: float = num_field(45.0, -90.0, 90.0, "degrees north")
    day_of_year: float = num_field(172.0, 1.0, 366.0, "the day of the year (1: 1 January)")
    year: int = int_field(2024, 1900, 2100, "the year of day_of_year")
    longitude: float | None = num_field(None, -180.0, 180.0, "degrees east; None: hours is solar time",
                                        optional=True)
    utc_offset: float | None = num_field(None, -14.0, 14.0, "with a longitude: hours from UTC of the clock's zone "
                                         "(None: the longitude's nominal zone, round(longitude / 15))",
                                         optional=True)


@dataclass(slots=True)
class TimeOfDay:
    """The running clock (a resource the daylight system advances every frame): ``hours`` in [0, 24),
    solar or clock time as :class:`DaylightSettings` says; every assignment is checked (0..24, 24 is
    midnight as 0 is)."""
    hours: float = 10.0

    def __setattr__(self, name: str, value) -> None:
        object.__setattr__(self, name, check_num("TimeOfDay", "hours", value, 0.0, 24.0) if name == "hours" else value)


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
        return solar_direction(self.time_of_day.hours, s.latitude, s.day_of_year, s.year, s.longitude, s.utc_offset)

    def advance(self, app) -> None:
        """System: advance the clock by ``speed × dt`` and write the Sun's direction, colour and ambient."""
        tod = self.time_of_day
        tod.hours = (tod.hours + self.settings.speed * app.clock.dt) % 24.0
        sun = app.init_resource(Sun)
        sun.direction = self.sun_direction()
        color, ambient = sky_light(sun.direction)
        sun.color, sun.ambient = tuple(color), tuple(ambient)

    def build(self, app) -> None:
        app.insert_resource(self.time_of_day)
        self.advance(app)        # the Sun is right from the start, whatever runs first at start-up
        app.add_system(self.advance, "update", label="daylight")
        app.add_system(self.advance, "startup", label="daylight_start")
