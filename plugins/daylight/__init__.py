"""Time of day → sun position, sun colour and sky ambient: the day–night cycle every effect reads.

``DaylightPlugin`` (its :class:`DaylightSettings`: start time, how fast time runs, latitude, day
of the year, year, optional longitude and time zone) keeps a :class:`TimeOfDay` resource (the running local solar time) and, each frame, writes the :class:`atmos.lighting.Sun` resource: its
direction from the solar position, its colour and the ambient sky colour from
:func:`atmos.lighting.sky_light` (reddened near the horizon, zero at night).
"""
from atmos.plugins.daylight.solar_position import solar_direction, solar_position
from atmos.plugins.daylight.time_of_day import DaylightPlugin, DaylightSettings, TimeOfDay

__all__ = ["DaylightPlugin", "DaylightSettings", "TimeOfDay", "solar_direction", "solar_position"]
