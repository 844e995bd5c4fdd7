"""The fog colour that follows the sky (``FogSettings.color_from = "sky"``): aerial perspective.

Far terrain, meshes and clouds fade toward the sky's own light, not toward one fixed grey. ``H`` is the
sky's radiance just above the horizon at ``SAMPLES`` azimuths round it (periodic, linear between):
the App's sky's light (:class:`atmos.plugins.sky.SkyLight`, published by the SkyPlugin) at this
frame's sun or, without a SkyPlugin, the Sun's ambient colour in every direction. A view ray takes
the horizon's light at the same angle from the sun: with s the unit sun direction, h = |s.xz| and
c = clamp(d·s / h, −1, 1), the mean of H at the sun's azimuth ± arccos c (:func:`sun_angle_table`
bakes that in float64 at even steps of sin(Δ/2) = sqrt((1 − c) / 2) from 0 to 1, Δ the angle from the
sun: fine where the glow round the sun changes fastest, and the shader needs a square root only). On the horizon that is H in the
ray's own azimuth (the sky is symmetric about the sun's); a ray down onto the ground under a low sun
is far from the sun and takes the sky's colour beside it, not the glow round the sun (no bright
pillar under the sun). Azimuth as in :meth:`atmos.lighting.Sun.from_angles`: ``atan2(x, -z)``.
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.sky.light import HORIZON_SAMPLES as SAMPLES   # one cache with the sky's other readers


def horizon_table(sun, sky_light=None, n: int = SAMPLES, altitude: float = 0.0) -> np.ndarray:
    """(n, 3) float64 linear horizon radiance for ``sun`` (an :class:`atmos.Sun`): the App's sky's
    (``sky_light``, the :class:`~atmos.plugins.sky.SkyLight` a SkyPlugin publishes, seen from the
    camera's ``altitude`` in m) or, without one, the Sun's ambient in every direction."""
    if sky_light is None:
        return np.tile(np.asarray(sun.ambient, np.float64), (n, 1))
    return sky_light.horizon(sun, altitude, n)


ZENITH = (0.0, 1.0, 0.0)
MIN_HORIZONTAL = 1e-6       # |s.xz| below this: the sun at the zenith, every azimuth alike


def horizon_at(table, azimuth) -> np.ndarray:
    """(..., 3) the horizon ``table`` (n, 3) at ``azimuth`` (radians, atan2(x, -z)), linear, periodic."""
    table = np.asarray(table, np.float64)
    n = len(table)
    u = (np.asarray(azimuth, np.float64) / (2.0 * np.pi)) % 1.0 * n
    i0 = np.floor(u).astype(int) % n
    t = (u - np.floor(u))[..., None]
    return (1.0 - t) * table[i0] + t * table[(i0 + 1) % n]


def sun_angle_table(table, sun_dir=ZENITH) -> np.ndarray:
    """(n, 3) float64: the horizon ``table`` (n azimuths) at the angles Δ_i = 2 arcsin(i / (n − 1)) from
    the sun's azimuth, each the mean of the two sides."""
    s = np.asarray(sun_dir, np.float64)
    table = np.asarray(table, np.float64)
    sun_azimuth = np.arctan2(s[0], -s[2])
    delta = 2.0 * np.arcsin(np.linspace(0.0, 1.0, len(table)))
    return 0.5 * (horizon_at(table, sun_azimuth + delta) + horizon_at(table, sun_azimuth - delta))


def sky_sun(sun) -> tuple:
    """The direction the sky's colour is read round: ``sun``'s (an :class:`atmos.Sun`), the zenith without one."""
    return ZENITH if sun is None else tuple(map(float, sun.direction))


def shader_table(table, sun) -> np.ndarray:
    """float32 (n, 3): what ``fog/color.glsl`` reads (its ``fog_horizon``): the horizon ``table`` by
    angle from ``sun`` (:func:`sun_angle_table` round :func:`sky_sun`)."""
    return sun_angle_table(table, sky_sun(sun)).astype(np.float32)


def sun_angle(directions, sun_dir=ZENITH) -> np.ndarray:
    """(...) sin(Δ/2) of the horizontal angle Δ from the sun a view ray takes its light at: with
    c = clamp(d·s / |s.xz|, −1, 1), sqrt((1 − c) / 2) (the sun at the zenith: 0 or 1)."""
    d = np.asarray(directions, np.float64)
    s = np.asarray(sun_dir, np.float64)
    c = np.clip(d @ s / max(float(np.hypot(s[0], s[2])), MIN_HORIZONTAL), -1.0, 1.0)
    return np.sqrt(0.5 - 0.5 * c)


def sky_fog_color(directions, table, fog_color, sun_dir=ZENITH) -> np.ndarray:
    """float64 (..., 3) in-scattered colour ``fog_color ⊙`` the horizon light at the view ray's angle
    from the sun (:func:`sun_angle`), for view ``directions`` (..., 3); ``table`` from
    :func:`horizon_table` (the reference of ``fog/color.glsl``'s ``in_color``, which reads
    :func:`sun_angle_table`)."""
    angles = sun_angle_table(table, sun_dir)
    n = len(angles)
    u = sun_angle(directions, sun_dir) * (n - 1)
    i0 = np.minimum(np.floor(u).astype(int), n - 2)
    t = (u - i0)[..., None]
    return np.asarray(fog_color, np.float64) * ((1.0 - t) * angles[i0] + t * angles[i0 + 1])
