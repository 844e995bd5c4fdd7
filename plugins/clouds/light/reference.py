"""Float64 numpy references of cloud shading: the exact transmittance and the shear-warp scheme.

The input checks and the slice plan they share with the GPU are in :mod:`atmos.plugins.clouds.light.grid`.

The quantity (index space, voxel ``i`` centred at integer ``i``, the volume is the box
``[-0.5, n-0.5]`` per axis)::

    T(p) = exp(-sigma * integral_0^t_exit rho(p + s u) ds)

``u`` is the unit sun direction, ``rho`` the density interpolated trilinearly between voxel centres,
clamped to the edge value in the outer half cell, and zero outside the box.

* :func:`transmittance_exact` integrates this *exactly* (to float64 rounding): because every ray
  starts on a voxel centre, all rays cross the integer planes (where the trilinear pieces change) and
  the half-integer planes (the box faces) at the same distances ``m / (2|u_a|)``. Between two such
  distances the density along the ray is a product of three linear functions of ``s`` -- a cubic --
  which two-point Gauss-Legendre integrates exactly. The trilinear weights at each Gauss point are
  the same for every voxel, so each point costs a few separable ``np.take`` lerps over the volume.
* :func:`shear_warp_scheme` is the shear-warp algorithm of :mod:`.shear_warp` in float64 (same
  geometry, same formulas), so the GPU can be compared with its own algorithm tightly and the
  algorithm with the exact reference separately. ``fixed_ratio=True`` gives the thesis's model.
"""
from __future__ import annotations

import itertools
import math

import numpy as np

from atmos.checks import check_sun_dir
# the input checks and the slice geometry are the GPU side's own (atmos.plugins.clouds.light.grid); kept here by name
from atmos.plugins.clouds.light.grid import (LATERAL, MAJOR_ORDER, SCALES, SIGMA_MAX, TAU_MAX, SlicePlan,  # noqa: F401
                                check_density, check_scale, check_sigma, shading_shape)


# -- geometry --------------------------------------------------------------------------------------
def exit_fraction(q, v: float, n: int):
    """Fraction of one step ``v`` (one lateral axis) before a ray from integer ``q`` leaves [-0.5, n-0.5]."""
    q = np.asarray(q, dtype=np.float64)
    if v > 0:
        return (n - 0.5 - q) / v
    if v < 0:
        return (q + 0.5) / -v
    return np.full_like(q, np.inf)


# -- interpolation ---------------------------------------------------------------------------------
def multilinear(grid: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Clamp-to-edge multilinear samples of an n-d ``grid`` at index-space ``points`` (..., n)."""
    n = np.array(grid.shape)
    p = np.clip(points, 0, n - 1)
    i0 = np.floor(p).astype(np.int64)
    fr = p - i0
    i1 = np.minimum(i0 + 1, n - 1)
    out = np.zeros(p.shape[:-1])
    for corner in itertools.product((0, 1), repeat=grid.ndim):
        weight = np.ones(p.shape[:-1])
        for axis, c in enumerate(corner):
            weight = weight * (fr[..., axis] if c else 1 - fr[..., axis])
        out += weight * grid[tuple((i1 if c else i0)[..., axis] for axis, c in enumerate(corner))]
    return out


trilinear = bilinear = multilinear      # the names the 3D and 2D callers use


def catmull_rom(t: np.ndarray) -> tuple:
    """Catmull-Rom weights of the taps at -1, 0, 1, 2 for fractions ``t``."""
    t2, t3 = t * t, t * t * t
    return (0.5 * (-t3 + 2 * t2 - t), 0.5 * (3 * t3 - 5 * t2 + 2), 0.5 * (-3 * t3 + 4 * t2 + t), 0.5 * (t3 - t2))


def taps(i: np.ndarray, n: int, v: float) -> tuple[np.ndarray, np.ndarray]:
    """Index and sign of lateral tap ``i`` of a slice of ``n`` texels whose sun-facing side (the
    one ``v`` points to) mirrors *oddly* about the face (optical depth 0 there, linear through it);
    the other side clamps to the edge."""
    sign = np.ones(np.shape(i))
    if v > 0:
        beyond = i > n - 1
        i = np.where(beyond, 2 * n - 1 - i, i)
        sign = np.where(beyond, -1.0, 1.0)
    elif v < 0:
        beyond = i < 0
        i = np.where(beyond, -1 - i, i)
        sign = np.where(beyond, -1.0, 1.0)
    return np.clip(i, 0, n - 1), sign


def cubic(plane: np.ndarray, y: np.ndarray, v=(0.0, 0.0)) -> np.ndarray:
    """Bicubic (Catmull-Rom) samples of the previous slice's optical depth at (..., 2) positions.

    Taps beyond a sun-facing face are odd mirrors (:func:`taps`); the result is limited to the range
    of the four nearest taps and to >= 0, so optical depth never drops along a ray."""
    n = plane.shape
    i0 = np.floor(y).astype(np.int64)
    fr = y - i0
    w = catmull_rom(fr[..., 0]), catmull_rom(fr[..., 1])
    out = np.zeros(y.shape[:-1])
    lo = np.full(y.shape[:-1], np.inf)
    hi = np.full(y.shape[:-1], -np.inf)
    ta = [taps(i0[..., 0] + k - 1, n[0], v[0]) for k in range(4)]
    tb = [taps(i0[..., 1] + k - 1, n[1], v[1]) for k in range(4)]
    for i in range(4):
        for k in range(4):
            value = plane[ta[i][0], tb[k][0]] * ta[i][1] * tb[k][1]
            out += w[0][i] * w[1][k] * value
            if i in (1, 2) and k in (1, 2):
                lo = np.minimum(lo, value)
                hi = np.maximum(hi, value)
    return np.maximum(np.clip(out, lo, hi), 0.0)


def lerp_matrix(positions: np.ndarray, n: int) -> np.ndarray:
    """(len(positions), n) matrix of clamp-to-edge linear-interpolation weights (1D, index space)."""
    p = np.clip(positions, 0, n - 1)
    i0 = np.floor(p).astype(np.int64)
    fr = p - i0
    i1 = np.minimum(i0 + 1, n - 1)
    m = np.zeros((len(p), n))
    rows = np.arange(len(p))
    np.add.at(m, (rows, i0), 1 - fr)
    np.add.at(m, (rows, i1), fr)
    return m


def _apply(volume: np.ndarray, mats) -> np.ndarray:
    for axis, m in enumerate(mats):
        volume = np.moveaxis(np.tensordot(m, volume, axes=([1], [axis])), 0, axis)
    return volume


def downsample(density: np.ndarray, scale: int) -> np.ndarray:
    """Coarse density for ``scale``: the mean of scale**3 trilinear samples per coarse cell (GPU's rule)."""
    if scale == 1:
        return np.asarray(density, dtype=np.float64)
    mats = []
    for n, m in zip(density.shape, shading_shape(density.shape, scale)):
        h = n / m
        sub = ((np.arange(m)[:, None] + (np.arange(scale)[None, :] + 0.5) / scale) * h - 0.5).ravel()
        mats.append(lerp_matrix(sub, n).reshape(m, scale, n).mean(axis=1))
    return _apply(np.asarray(density, dtype=np.float64), mats)


def upsample(coarse: np.ndarray, shape) -> np.ndarray:
    """Trilinear samples of a coarse grid at the fine voxel centres of ``shape`` (the same box)."""
    mats = [lerp_matrix((np.arange(n) + 0.5) * m / n - 0.5, m) for n, m in zip(shape, coarse.shape)]
    return _apply(coarse, mats)


# -- the exact reference ---------------------------------------------------------------------------
def exit_distance(shape, u: np.ndarray) -> np.ndarray:
    """Distance (cells) from every voxel centre along ``u`` to the box boundary, shape ``shape``."""
    t = np.full(shape, np.inf)
    for a, n in enumerate(shape):
        if u[a] == 0:
            continue
        i = np.arange(n, dtype=np.float64)
        d = (n - 0.5 - i) / u[a] if u[a] > 0 else (i + 0.5) / -u[a]
        t = np.minimum(t, d.reshape([-1 if k == a else 1 for k in range(3)]))
    return t


def optical_depth_exact(density, sun_dir) -> np.ndarray:
    """Exact ``integral rho ds`` from every voxel centre toward the sun (float64, see module docstring)."""
    d = np.asarray(density, dtype=np.float64)
    u = check_sun_dir(sun_dir)
    shape = d.shape
    t_exit = exit_distance(shape, u)
    t_max = float(t_exit.max())
    breaks = [np.zeros(1), np.array([t_max])]
    for a, n in enumerate(shape):
        if u[a] != 0:
            m = np.arange(1, 2 * n + 1)
            breaks.append(m[m / (2 * abs(u[a])) < t_max] / (2 * abs(u[a])))
    breaks = np.unique(np.concatenate(breaks))
    g = 0.5 / math.sqrt(3.0)
    idx = [np.arange(n) for n in shape]
    tau = np.zeros(shape)
    for t0, t1 in zip(breaks[:-1], breaks[1:]):
        inside = t_exit > 0.5 * (t0 + t1)
        if not inside.any():
            continue
        for t in (0.5 * (t0 + t1) - g * (t1 - t0), 0.5 * (t0 + t1) + g * (t1 - t0)):
            v = d
            for a, n in enumerate(shape):
                o = t * u[a]
                fl = math.floor(o)
                fr = o - fl
                i0 = np.clip(idx[a] + fl, 0, n - 1)
                i1 = np.clip(idx[a] + fl + 1, 0, n - 1)
                v = np.take(v, i0, axis=a) * (1 - fr) + np.take(v, i1, axis=a) * fr
            tau += np.where(inside, 0.5 * (t1 - t0) * v, 0.0)
    return tau


def transmittance_exact(density, sun_dir, sigma) -> np.ndarray:
    """Float64 exact transmittance toward the sun of every voxel centre (see module docstring)."""
    d = check_density(density)
    s = check_sigma(sigma)
    if s == 0:
        return np.ones(d.shape)
    with np.errstate(over="ignore"):
        return np.exp(-np.minimum(s * optical_depth_exact(d, sun_dir), TAU_MAX))


# -- the shear-warp scheme in float64 --------------------------------------------------------------
def shear_warp_scheme(density, sun_dir, sigma, scale: int = 1, fixed_ratio: bool = False,
                      levels: int = 0) -> np.ndarray:
    """The GPU shear-warp algorithm in float64 (returns T on the fine grid of ``density``).

    True-path model: for voxel q of slice j, ``f`` = the fraction of one step toward the sun before
    the ray leaves the box (1 inside, 0.5 on the light-side slice, less near a lateral face)::

        f >= 1:  tau = tau_prev(q + v) + sigma * L * (rho(q) + rho(q + v)) / 2
        f <  1:  tau = sigma * f * L * (rho(q) + rho(q + f v)) / 2

    ``tau_prev`` is bicubic in the previous slice, limited, odd-mirrored across a sun-facing face
    (``cubic``: 0 on the face, no diffusion of the linear profile there), ``L``
    the true length of one slice step. ``fixed_ratio``: the thesis's model, ``T = T_prev(q + v) *
    exp(-sigma * rho(q + v))`` per slice whatever the angle, 1 on the light-side slice, optionally
    rounded to ``levels`` steps (255: 8-bit storage).
    """
    fine = check_density(density)
    u = check_sun_dir(sun_dir)
    sigma = min(check_sigma(sigma), SIGMA_MAX)
    scale = check_scale(scale)
    d = downsample(fine.astype(np.float64), scale)
    spacing = np.array(fine.shape) / np.array(d.shape)
    plan = SlicePlan(d.shape, u, spacing)
    a, (b, c) = plan.axis, plan.lateral
    dp = np.transpose(d, (a, b, c))
    na, nb, nc = dp.shape
    vb, vc = plan.step[b], plan.step[c]
    qb, qc = np.meshgrid(np.arange(nb, dtype=np.float64), np.arange(nc, dtype=np.float64), indexing="ij")
    fl = np.minimum(exit_fraction(qb, vb, nb), exit_fraction(qc, vc, nc))
    step = np.array([plan.sign, vb, vc])
    out = np.empty_like(dp)
    prev = None
    for j in plan.order:
        p = np.stack([np.full_like(qb, j), qb, qc], axis=-1)
        y = np.stack([qb + vb, qc + vc], axis=-1)
        if fixed_ratio:
            if prev is None:
                value = np.ones_like(qb)
            else:
                value = bilinear(prev, y) * np.exp(-sigma * trilinear(dp, p + step))
                if levels:
                    value = np.round(value * levels) / levels
            out[j] = value
        else:
            f = np.minimum(fl, 0.5 if prev is None else 1.0)
            rho0 = dp[j]
            with np.errstate(over="ignore", invalid="ignore"):
                full = f >= 1
                rho1 = trilinear(dp, p + np.where(full, 1.0, f)[..., None] * step)
                tau = sigma * (0.5 * rho0 + 0.5 * rho1) * (np.where(full, 1.0, f) * plan.length)
                if prev is not None:
                    tau = tau + np.where(full, cubic(prev, y, (vb, vc)), 0.0)
                value = np.minimum(tau, TAU_MAX)
            out[j] = np.exp(-value)
        prev = value
    result = np.transpose(out, np.argsort((a, b, c)))
    return upsample(result, fine.shape) if scale > 1 else result
