"""numpy float64 reference of the region volume and of the probabilities derived from it.

Region volume (thesis sec. 4.3.3.1-4.3.3.3): for every cell (i, j, k) of an (nx, ny, nz) volume,
with its centre p = (i + 0.5, j + 0.5, k + 0.5) in volume-local cells,

    R(p) = max(0, max over ellipsoids e of (1 - r_e(p))),
    r_e(p) = |( (cos·dx + sin·dz) / rx,  dy / ry,  (-sin·dx + cos·dz) / rz )|,  d = p - c_e,

i.e. 1 at the centre falling *linearly* with the normalized ellipsoid distance r to 0 on the
surface (the thesis: "a linear interpolation between the center and the surface"), 0 outside
every ellipsoid. Ellipsoids with a radius <= 0 (fully shrunk) contribute nothing.

Ellipsoid arrays are (n, 8) with the columns of :data:`.components.COLUMNS`: centre relative to the volume
origin, yaw (radians, around y), the radii already multiplied by the shrink scale, and a pad.
"""
from __future__ import annotations

import numpy as np
from atmos.plugins.clouds.weather.components import check_ellipsoid_array


def region_volume(ellipsoids, shape) -> np.ndarray:
    """The region volume as float64 (nx, ny, nz), indexed [x, y, z]."""
    a = check_ellipsoid_array(ellipsoids).astype(np.float64)
    shape = tuple(int(n) for n in shape)
    out = np.zeros(shape, np.float64)
    size = np.array(shape)
    for row in a:
        c, yaw, r = row[0:3], row[3], row[4:7]
        if not (r > 0).all():
            continue
        reach = r.max() + 1.0  # a generous axis-aligned box: cells outside it are outside the ellipsoid
        lo = np.clip(np.floor(c - reach).astype(np.int64), 0, size)
        hi = np.clip(np.ceil(c + reach).astype(np.int64) + 1, 0, size)
        if (hi <= lo).any():
            continue
        px, py, pz = np.meshgrid(*(np.arange(l, h) + 0.5 for l, h in zip(lo, hi)), indexing="ij")
        dx, dy, dz = px - c[0], py - c[1], pz - c[2]
        cs, sn = np.cos(yaw), np.sin(yaw)
        lx = (cs * dx + sn * dz) / r[0]
        ly = dy / r[1]
        lz = (-sn * dx + cs * dz) / r[2]
        value = 1.0 - np.sqrt(lx * lx + ly * ly + lz * lz)
        block = out[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]]
        np.maximum(block, value, out=block)
    return out


def probabilities(region, hum_scale=0.1, act_scale=0.001, ext_scale=0.1, vanish_threshold=0.001):
    """(p_hum, p_act, p_ext) as float32 arrays of the region's shape (thesis Appendix A).

    ``p_hum = hum_scale·R``, ``p_act = act_scale·R``, ``p_ext = ext_scale·(1 − R)``, and
    ``p_ext = 1`` where ``R <= vanish_threshold``: cells outside every ellipsoid lose their cloud
    (the thesis's "remove cloud particles outside of the defined ellipsoids").
    Pass a :class:`WeatherSettings` as ``hum_scale`` to take all four scales from it.
    """
    if hasattr(hum_scale, "hum_scale"):
        p = hum_scale
        hum_scale, act_scale, ext_scale, vanish_threshold = p.hum_scale, p.act_scale, p.ext_scale, p.vanish_threshold
    r = np.asarray(region, dtype=np.float64)
    p_hum = hum_scale * r
    p_act = act_scale * r
    p_ext = np.where(r <= vanish_threshold, 1.0, ext_scale * (1.0 - r))
    return p_hum.astype(np.float32), p_act.astype(np.float32), p_ext.astype(np.float32)
