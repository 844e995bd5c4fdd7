"""The fog colour that follows the sky (``FogSettings.color_from = "sky"``): aerial perspective.

Far terrain, meshes and clouds fade toward the sky they stand against, not toward one fixed grey:
the in-scattered colour of a pixel is ``fog_color ⊙ H(azimuth of its view ray)``, where ``H`` is the
sky's radiance just above the horizon (``ELEVATION``) at ``SAMPLES`` azimuths round the horizon,
interpolated linearly (periodic). ``H`` comes from the App's SkyPlugin at this frame's sun: the
Preetham sky (its turbidity and scale, :func:`atmos.plugins.sky.reference.sky_radiance`) or the
physical one (its atmosphere, from the camera's altitude), or,
without a SkyPlugin, is the Sun's ambient colour in every direction. Azimuth as in
:meth:`atmos.lighting.Sun.from_angles`: ``atan2(x, -z)``, 0 toward -z, increasing toward +x.
"""
from __future__ import annotations

import math

import numpy as np

SAMPLES = 32
ELEVATION = math.radians(2.0)


def horizon_directions(n: int = SAMPLES) -> np.ndarray:
    """(n, 3) unit directions ``ELEVATION`` above the horizon at azimuths 2π i / n."""
    a = 2.0 * np.pi * np.arange(n) / n
    c = math.cos(ELEVATION)
    return np.stack([np.sin(a) * c, np.full(n, math.sin(ELEVATION)), -np.cos(a) * c], -1)


def horizon_colors(sun, sky_settings=None, n: int = SAMPLES, altitude: float = 0.0) -> np.ndarray:
    """(n, 3) float64 linear radiance of the horizon sky for ``sun`` (an :class:`atmos.Sun`):
    ``sky_settings`` (a SkySettings) gives its sky, Preetham or physical (seen from the camera's
    ``altitude`` in m: :func:`atmos.plugins.sky.sun_light.horizon_radiance`); None: the Sun's
    ambient everywhere."""
    if sky_settings is None:
        return np.tile(np.asarray(sun.ambient, np.float64), (n, 1))
    if sky_settings.model == "physical":
        from atmos.plugins.sky.sun_light import horizon_radiance
        return horizon_radiance(horizon_directions(n), sun.direction, altitude, sky_settings.atmosphere,
                                sky_settings.night)
    from atmos.plugins.sky.reference import sky_radiance
    return sky_radiance(horizon_directions(n), np.asarray(sun.direction, np.float64),
                        sky_settings.turbidity, sky_settings.scale, sky_settings.night)


def sky_fog_color(directions, table, fog_color) -> np.ndarray:
    """float64 (..., 3) in-scattered colour ``fog_color ⊙ H(azimuth)`` for view ``directions`` (..., 3),
    ``table`` from :func:`horizon_colors` (the reference of ``fog/fog.frag``'s ``in_color``)."""
    d = np.asarray(directions, np.float64)
    table = np.asarray(table, np.float64)
    n = len(table)
    u = (np.arctan2(d[..., 0], -d[..., 2]) / (2.0 * np.pi)) % 1.0 * n
    i0 = np.floor(u).astype(int) % n
    t = (u - np.floor(u))[..., None]
    return np.asarray(fog_color, np.float64) * ((1.0 - t) * table[i0] + t * table[(i0 + 1) % n])
