"""Time of day → sun position, sun colour and sky ambient: the day–night cycle every effect reads.

``DaylightPlugin`` keeps a :class:`TimeOfDay` resource (local solar time, latitude, day of the
year, how fast time runs) and, each frame, writes the :class:`atmos.lighting.Sun` resource: its
direction from the solar position, its colour and the ambient sky colour from
:func:`atmos.plugins.shading.scattering.sky_light` (reddened near the horizon, zero at night).
"""
from atmos.plugins.daylight.time_of_day import DaylightPlugin, TimeOfDay, solar_direction

__all__ = ["DaylightPlugin", "TimeOfDay", "solar_direction"]
