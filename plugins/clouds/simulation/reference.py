"""numpy float64 references of cloud field smoothing (eq. 2.11 over space) and density maps (7.2.2).

They define what the GPU versions in :mod:`.smoothing` and :mod:`.density_maps` compute (the
parameter checks both share live in those modules). Arrays are indexed ``[x, y, z]``, y is height.

Smoothing: ``q(x, y, z) = sum_d w(d) cld(x + d) / sum_d w(d)`` over the box ``|d_a| <= r_a``, with
separable integer weights ``w(d) = wx(dx) * wy(dy) * wz(dz)``:

* ``"tent"``: ``w_a(d) = r_a + 1 - |d|`` (nearer cells weigh more; the thesis's w),
* ``"box"``: ``w_a(d) = 1`` (eq. 2.11 with w = 1, a plain average).

Cells outside the volume count as 0 and the sum is *not* renormalized at the borders (a full
neighbourhood gives exactly 1.0; a cloud touching a face of the volume thins out there, as if
the outside were clear sky). Any density above 0 is raised to ``min_density`` (the GPU uses the
smallest normal half float for r16f targets), so a cell with any cld in its neighbourhood is
strictly positive and stays so after rounding to the texture format.
"""
from __future__ import annotations

import numpy as np

# the parameter checks and weights are the GPU side's own; kept here by name
from atmos.plugins.clouds.simulation.density_maps import group_grid
from atmos.plugins.clouds.simulation.smoothing import (F16_MIN_NORMAL, MAX_RADIUS, WEIGHTS,  # noqa: F401
                                            axis_weights, check_radius, check_weights)


def smooth(cld, radius=(1, 1, 1), weights: str = "tent", min_density: float = 0.0) -> np.ndarray:
    """Smoothed density (float64 ``[x, y, z]``) of the bool field ``cld``; see the module docstring."""
    cld = np.asarray(cld)
    if cld.ndim != 3 or cld.dtype != np.bool_:
        raise ValueError(f"cld must be a 3D bool array [x, y, z], got {cld.dtype} of shape {cld.shape}")
    radius = check_radius(radius)
    acc = cld.astype(np.int64)
    total = 1
    for axis, r in enumerate(radius):
        w = axis_weights(weights, r)
        total *= int(w.sum())
        pad = [(0, 0)] * 3
        pad[axis] = (r, r)
        padded = np.pad(acc, pad)
        n = acc.shape[axis]
        acc = sum(int(w[i]) * np.take(padded, np.arange(i, i + n), axis=axis) for i in range(2 * r + 1))
    q = acc / float(total)
    return np.where(acc > 0, np.maximum(q, min_density), 0.0)


def density_maps(density, band_height: int = 4, group_size=(32, 32)):
    """``(sums, max_maps)`` of a density volume ``[x, y, z]``, float64.

    ``sums[0]`` is the sum over all heights (nx, nz); ``sums[1 + b]`` the sum over heights
    ``[b * band_height, min((b + 1) * band_height, ny))``. ``max_maps[m][gx, gz]`` is the max of
    ``sums[m]`` over the segment ``x in [gx * group_x, min((gx + 1) * group_x, nx))`` (same for z).
    """
    density = np.asarray(density, dtype=np.float64)
    nx, ny, nz = density.shape
    bands = -(-ny // band_height)
    sums = np.empty((bands + 1, nx, nz))
    sums[0] = density.sum(axis=1)
    for b in range(bands):
        sums[1 + b] = density[:, b * band_height:(b + 1) * band_height].sum(axis=1)
    gx, gz = group_grid(nx, nz, group_size)
    sx, sz = group_size
    maxes = np.empty((bands + 1, gx, gz))
    for i in range(gx):
        for k in range(gz):
            maxes[:, i, k] = sums[:, i * sx:(i + 1) * sx, k * sz:(k + 1) * sz].max(axis=(1, 2))
    return sums, maxes
