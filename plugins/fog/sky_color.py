"""The fog colour that follows the sky (``FogSettings.color_from = "sky"``): aerial perspective.

Far terrain, meshes and clouds fade toward the sky they stand against, not toward one fixed grey:
the in-scattered colour of a pixel is ``fog_color ⊙ H(azimuth of its view ray)``, where ``H`` is the
sky's radiance just above the horizon at ``SAMPLES`` azimuths round it, interpolated linearly
(periodic). ``H`` is the App's sky's light (:class:`atmos.plugins.sky.SkyLight`, published by the
SkyPlugin) at this frame's sun, or, without a SkyPlugin, the Sun's ambient colour in every direction.
Azimuth as in :meth:`atmos.lighting.Sun.from_angles`: ``atan2(x, -z)``, 0 toward -z, increasing toward +x.
"""
from __future__ import annotations

import numpy as np

SAMPLES = 32


def horizon_table(sun, sky_light=None, n: int = SAMPLES, altitude: float = 0.0) -> np.ndarray:
    """(n, 3) float64 linear horizon radiance for ``sun`` (an :class:`atmos.Sun`): the App's sky's
    (``sky_light``, the :class:`~atmos.plugins.sky.SkyLight` a SkyPlugin publishes, seen from the
    camera's ``altitude`` in m) or, without one, the Sun's ambient in every direction."""
    if sky_light is None:
        return np.tile(np.asarray(sun.ambient, np.float64), (n, 1))
    return sky_light.horizon(sun, altitude, n)


def sky_fog_color(directions, table, fog_color) -> np.ndarray:
    """float64 (..., 3) in-scattered colour ``fog_color ⊙ H(azimuth)`` for view ``directions`` (..., 3),
    ``table`` from :func:`horizon_table` (the reference of ``fog/fog.frag``'s ``in_color``)."""
    d = np.asarray(directions, np.float64)
    table = np.asarray(table, np.float64)
    n = len(table)
    u = (np.arctan2(d[..., 0], -d[..., 2]) / (2.0 * np.pi)) % 1.0 * n
    i0 = np.floor(u).astype(int) % n
    t = (u - np.floor(u))[..., None]
    return np.asarray(fog_color, np.float64) * ((1.0 - t) * table[i0] + t * table[(i0 + 1) % n])
