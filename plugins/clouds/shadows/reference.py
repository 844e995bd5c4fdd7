"""numpy float64 reference of the ground-shadow factor (thesis 7.3.1), and the sun weight both sides use.

A surface point P is projected along the direction toward the sun onto the middle plane of the cloud
layer, Q = P + s·max(y_mid − P.y, 0)/s.y, and the top-view summed density (layer 0 of the density
maps, mix(A, B, t)) is read there bilinearly, zero outside the volume, times the volume's edge
fade at Q (:mod:`atmos.plugins.clouds.volume.edge`). The optical depth ``tau = sigma·strength·sum·fade·above`` (``above``: the fraction of the layer's height above P, 1 on the
ground below it, 0 above its top) dims the direct light only:
``factor = mix(1, exp(−tau), weight)`` with ``weight`` from :func:`direct_weight`.
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.clouds.volume.edge import edge_weight, footprint_uv
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.volume.shape import centre_shift, typed_column
from atmos.plugins.clouds.light.reference import bilinear
from atmos.lighting import unit_sun
from atmos.plugins.clouds.shadows.plugin import direct_weight  # noqa: F401  (the pass's own)

MIN_SUN_HEIGHT = 1e-4   # the projection's divisor never gets smaller (weight is 0 there anyway)


def zero_border_bilinear(plane: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Bilinear samples of a 2D ``plane`` at texel coordinates ``p`` (..., 2), texel i centred at i,
    zero outside (OpenGL's clamp-to-border with a black border)."""
    n = np.array(plane.shape, np.float64)
    inside = np.all((p > -1.0) & (p < n), axis=-1)
    q = np.where(inside[..., None], p, -1.0) + 1.0
    return np.where(inside, bilinear(np.pad(np.asarray(plane, np.float64), 1), q), 0.0)


def shifted(plane: np.ndarray, shift) -> np.ndarray:
    """``plane`` (nx, nz) read at ``[i + shift.x, k + shift.z]``, zero past its edge."""
    n = np.array(plane.shape)
    i, k = np.arange(n[0])[:, None] + int(shift[0]), np.arange(n[1])[None, :] + int(shift[2])
    inside = (i >= 0) & (i < n[0]) & (k >= 0) & (k < n[1])
    return np.where(inside, plane[np.clip(i, 0, n[0] - 1), np.clip(k, 0, n[1] - 1)], 0.0)


def shadow_factor(points, sums_a, sums_b, t: float, sun_direction, weight: float, extinction: float,
                  layout: CloudLayout, a_shift=(0, 0, 0), edge_fade: float = 0.0, far=None,
                  cloud_type=None, type_map=None) -> np.ndarray:
    """Factor (...,) the colour at world ``points`` (..., 3) is multiplied by; ``sums_a/b`` (nx, nz)
    the all-heights top-view maps of sets A and B; ``extinction`` = sigma·strength; ``layout`` B's
    world placement (the sprite renderer's rule); ``a_shift`` cells from B's column to A's
    (:attr:`CloudSets.a_shift`), A zero past its edge; ``edge_fade`` the CloudSettings'."""
    points = np.asarray(points, np.float64)
    s = unit_sun(sun_direction)
    if s is None or weight <= 0.0:
        return np.ones(points.shape[:-1])
    tau = sun_optical_depth(points, sums_a, sums_b, t, s, extinction, layout, a_shift, edge_fade, far,
                            cloud_type, type_map)
    return 1.0 - weight * (1.0 - np.exp(-tau))


def sun_optical_depth(points, sums_a, sums_b, t: float, sun_dir, extinction: float, layout: CloudLayout,
                      a_shift=(0, 0, 0), edge_fade: float = 0.0, far=None, cloud_type=None,
                      type_map=None) -> np.ndarray:
    """Optical depth (...,) from world ``points`` (..., 3) toward the sun (``sun_dir`` unit, y > 0)
    through the clouds: ``extinction · column · above`` (module docstring; shaders/clouds/volume/column.glsl);
    ``far``: None, or a function of world xz (..., 2) giving the far field's column optical depth there
    (``column_tau·strength·column_at_rank(rank)``, the column far.comp draws:
    :func:`atmos.plugins.clouds.far_field.reference.far_field_alpha`),
    added with the complementary edge weight ``(1 − edge)·above``. ``cloud_type``/``type_map``: the shape the
    clouds are drawn with (column.glsl typed_column, :func:`~atmos.plugins.clouds.volume.shape.typed_column`;
    both None: as simulated) turns the volume's column (``far`` gives its own, shaped by the caller), read
    where the sun's ray meets the shape's mass centre (:func:`~atmos.plugins.clouds.volume.shape.centre_shift`)."""
    points, s = np.asarray(points, np.float64), np.asarray(sun_dir, np.float64)
    sums = (1.0 - t) * shifted(np.asarray(sums_a, np.float64), a_shift) + t * np.asarray(sums_b, np.float64)
    lo, hi, cell = layout.lo, layout.hi, np.asarray(layout.cell, np.float64)
    y = points[..., 1]
    run = np.maximum(0.5 * (lo[1] + hi[1]) - y, 0.0) / max(s[1], MIN_SUN_HEIGHT)
    q = points + run[..., None] * s
    xz = q[..., [0, 2]] + centre_shift(q[..., 0], q[..., 2], s, hi[1] - lo[1], cloud_type, type_map, MIN_SUN_HEIGHT)
    texel = (xz - lo[[0, 2]]) / cell[[0, 2]] - 0.5        # map texel (i, k) centred at (i, k)
    edge = edge_weight(footprint_uv(layout, xz), edge_fade)
    column = typed_column(zero_border_bilinear(sums, texel), xz[..., 0], xz[..., 1], layout.shape[1], cloud_type,
                          type_map) * edge
    above = np.clip((hi[1] - y) / (hi[1] - lo[1]), 0.0, 1.0)
    tau = extinction * column * above
    if far is not None:
        tau = tau + far(xz) * (1.0 - edge) * above
    return tau
