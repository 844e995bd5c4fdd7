"""The Sun's colour and ambient and the fog's horizon colours from the physical sky (float64, CPU).

With ``SkySettings.model = "physical"`` the sky plugin's system ``sky_light`` (update and startup
stages, ordered after DaylightPlugin's ``daylight``/``daylight_start`` by label when those exist)
writes, for the Sun's direction and the camera's altitude:

- ``Sun.color`` = the sun's colour after its path through the atmosphere to the camera
  (:func:`atmos.plugins.sky.atmosphere.sun_radiance`, one transmittance lookup a frame), and
  ``Sun.color_by_altitude`` the same at any altitude (the cloud layers take it at theirs);
- ``Sun.ambient`` = the sky's irradiance on an upward surface / π from the same model
  (:func:`atmos.plugins.sky.atmosphere.ambient`), plus the sky's ``night`` term as the pass draws it.

The ambient and the horizon table depend only on the sun's elevation and the camera's altitude (the
sky is symmetric about the sun's vertical): both are computed at nodes ``ELEVATION_STEP`` apart in
sun elevation and at altitudes ``(k · ALTITUDE_ROOT_STEP)²`` m, each node once per settings, and
interpolated bilinearly between them. A node takes 3–5 ms of float64 marching: the nodes one elevation
step from those a frame used are baked ahead, at most one a frame (:func:`bake_ahead`, called by the sky
plugin's system), so a sun crossing a node finds it ready instead of baking five in one frame.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import Callable

import numpy as np

import atmos.plugins.sky.atmosphere as ref
from atmos.plugins.sky.atmosphere_settings import AtmosphereSettings
from atmos.plugins.sky.radiance import daylight

ELEVATION_STEP = 0.5            # degrees of sun elevation between nodes
ALTITUDE_ROOT_STEP = 10.0       # nodes at altitudes (10 k)² m: 0, 100, 400, 900 ... 40 000 m at k = 20
HORIZON_AZIMUTHS = 33           # horizon radiance nodes over 0..π from the sun's azimuth


def _sun_at(elevation_deg: float) -> np.ndarray:
    e = math.radians(elevation_deg)
    return np.array([math.cos(e), math.sin(e), 0.0])


MAX_NODES = 8192                # nodes kept (the oldest dropped first)
_NODES: dict = {}               # (bake, id(settings), *args) -> (settings, node): held, never a reused id
_USED: dict = {}                # keys used since the last bake_ahead -> their settings


def _node(bake: Callable, settings, *args) -> np.ndarray:
    """``bake(settings, *args)``, baked on first use and kept (MAX_NODES; keyed by the settings' identity:
    hashed in C, a settings object being replaced on any change)."""
    key = (bake, id(settings), *args)
    _USED[key] = settings
    entry = _NODES[key] if key in _NODES else None
    if entry is None or entry[0] is not settings:
        entry = _NODES[key] = (settings, bake(settings, *args))
        if len(_NODES) > MAX_NODES:
            del _NODES[next(iter(_NODES))]
    return entry[1]


def bake_ahead(nodes: int = 1) -> int:
    """Bake up to ``nodes`` of the nodes one elevation step from those used since the last call: a
    frame's spare work, so that a sun crossing a node finds it baked. Returns how many were baked."""
    baked, limit = 0, _ELEVATION_LIMIT
    for key, settings in _USED.items():
        bake, sid, i, *rest = key
        for n in (max(i - 1, -limit), min(i + 1, limit)):
            ahead = (bake, sid, n, *rest)
            if baked < nodes and (ahead not in _NODES or _NODES[ahead][0] is not settings):
                _NODES[ahead] = (settings, bake(settings, n, *rest))     # baked, not used
                baked += 1
    _USED.clear()
    return baked


def _bake_ambient(settings: AtmosphereSettings, i_elevation: int, k_altitude: int) -> np.ndarray:
    return ref.ambient(_sun_at(i_elevation * ELEVATION_STEP), (k_altitude * ALTITUDE_ROOT_STEP) ** 2, settings)


def _bake_horizon(settings: AtmosphereSettings, i_elevation: int, k_altitude: int, elevation: float) -> np.ndarray:
    """(HORIZON_AZIMUTHS, 3) radiance at ``elevation`` rad above the horizon, azimuths 0..π from the sun."""
    a = np.linspace(0.0, math.pi, HORIZON_AZIMUTHS)
    c = math.cos(elevation)
    dirs = np.stack([np.cos(a) * c, np.full_like(a, math.sin(elevation)), np.sin(a) * c], axis=-1)
    return ref.sky_radiance(dirs, _sun_at(i_elevation * ELEVATION_STEP), (k_altitude * ALTITUDE_ROOT_STEP) ** 2, settings)


def _nodes(sun_y: float, altitude: float):
    """[(weight, elevation node, altitude node)] of the bilinear interpolation (elevation nodes clamped
    to the zenith's and the nadir's)."""
    e = math.degrees(math.asin(min(max(sun_y, -1.0), 1.0))) / ELEVATION_STEP
    k = math.sqrt(max(altitude, 0.0)) / ALTITUDE_ROOT_STEP
    e0, k0 = math.floor(e), math.floor(k)
    fe, fk = e - e0, k - k0
    lo, hi = min(max(e0, -_ELEVATION_LIMIT), _ELEVATION_LIMIT), min(max(e0 + 1, -_ELEVATION_LIMIT), _ELEVATION_LIMIT)
    return [(w, i, j) for w, i, j in (((1 - fe) * (1 - fk), lo, k0), (fe * (1 - fk), hi, k0),
                                      ((1 - fe) * fk, lo, k0 + 1), (fe * fk, hi, k0 + 1)) if w > 0]


_ELEVATION_LIMIT = round(90.0 / ELEVATION_STEP)     # the nodes at the zenith and the nadir


def sun_color(sun_dir, altitude, settings: AtmosphereSettings) -> np.ndarray:
    """(3,) ``Sun.color``: the sun's colour seen from ``altitude`` m; an array of altitudes (n,) gives
    (n, 3) in one vectorised pass (``Sun.color_by_altitude``: a cloud layer's heights). Remembered for
    the last few directions and altitudes: the camera's and the cloud layers' are asked every frame."""
    heights = np.asarray(altitude, np.float64)
    direction = tuple(map(float, np.asarray(sun_dir, np.float64).reshape(3)))
    return _sun_color(direction, tuple(heights.reshape(-1).tolist()), settings).reshape(heights.shape + (3,)).copy()


@lru_cache(maxsize=16)
def _sun_color(sun_dir: tuple, altitudes: tuple, settings: AtmosphereSettings) -> np.ndarray:
    return ref.sun_radiance(np.array(sun_dir), np.array(altitudes), settings)


def sky_ambient(sun_dir, altitude: float, settings: AtmosphereSettings, night=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(3,) ``Sun.ambient``: the sky's irradiance / π (interpolated between nodes) plus ``night`` × the
    pass's night weight."""
    s = ref.unit(sun_dir)
    total = 0.0
    for w, i, j in _nodes(s[1], altitude):
        total = total + w * _node(_bake_ambient, settings, i, j)
    return total + np.asarray(night, np.float64) * (1.0 - float(daylight(s[1])))


def horizon_radiance(directions, sun_dir, altitude: float, settings: AtmosphereSettings,
                     night=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(n, 3) the physical sky's radiance along ``directions`` (n, 3), all at one elevation (the fog's
    horizon ring), from the nodes: interpolated over the sun's elevation, the altitude and the
    azimuth from the sun; plus the night term as the pass draws it."""
    d = np.asarray(directions, np.float64)
    s = ref.unit(sun_dir)
    elevation = math.asin(min(max(float(d[0, 1]), -1.0), 1.0))
    _, cos_az, _, _ = ref.view_angles(d, s)
    x = np.arccos(np.minimum(np.maximum(cos_az, -1.0), 1.0)) / math.pi * (HORIZON_AZIMUTHS - 1)
    i0 = np.minimum(np.floor(x).astype(int), HORIZON_AZIMUTHS - 2)
    f = (x - i0)[:, None]
    total = 0.0
    for w, i, j in _nodes(s[1], altitude):
        table = _node(_bake_horizon, settings, i, j, elevation)
        total = total + w * ((1 - f) * table[i0] + f * table[i0 + 1])
    return total + np.asarray(night, np.float64) * (1.0 - float(daylight(s[1])))
