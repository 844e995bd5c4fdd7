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
from atmos.glsl_math import catmull_rom_weights
# the input checks and the slice geometry are the GPU side's own (atmos.plugins.clouds.light.grid); kept here by name
from atmos.plugins.clouds.light.grid import (LATERAL, MAJOR_ORDER, SCALES, SIGMA_MAX, TAU_MAX, SlicePlan,  # noqa: F401
                                check_density, check_scale, check_sigma, shading_shape)


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

    True-path model (sun-aligned columns): column Q starts on the light-side slice at lateral ``Q`` and
    lies at ``Q - k v`` on the k-th slice (``v`` the lateral step toward the sun per slice). Along its own
    straight ray it adds, per slice, ``sigma * L * (t1 - t0) * (rho(t0) + rho(t1)) / 2`` over the part
    ``[t0, t1]`` of the step toward the previous slice (t = 0 here, 1 there; half a step on the
    light-side slice) that lies inside the box: no interpolation between columns, so no numerical
    diffusion. The warp: cell c of slice k takes the depth of the columns around ``c + k v`` bicubically
    (Catmull-Rom, limited to the four nearest), then ``T = exp(-depth)``. Where that cannot work (a tap
    beyond a face, or taps whose rays leave the box through different faces, where the depth bends:
    :func:`bends`) the cell marches its own ray toward the sun by the same steps. ``L`` is the true
    length of one slice step. ``fixed_ratio``: the thesis's model, ``T = T_prev(q + v) * exp(-sigma * rho(q + v))``
    per slice whatever the angle, 1 on the light-side slice, optionally rounded to ``levels`` steps
    (255: 8-bit storage).
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
    if fixed_ratio:
        out = _fixed_ratio(dp, plan, sigma, levels)
    else:
        out = _columns(dp, plan, sigma)
    result = np.transpose(out, np.argsort((a, b, c)))
    return upsample(result, fine.shape) if scale > 1 else result


def _fixed_ratio(dp: np.ndarray, plan: SlicePlan, sigma: float, levels: int) -> np.ndarray:
    """The thesis's slice-by-slice model on the (axis, b, c)-ordered density ``dp``."""
    _, nb, nc = dp.shape
    vb, vc = plan.lateral_step
    qb, qc = np.meshgrid(np.arange(nb, dtype=np.float64), np.arange(nc, dtype=np.float64), indexing="ij")
    step = np.array([plan.sign, vb, vc])
    out = np.empty_like(dp)
    prev = None
    for j in plan.order:
        p = np.stack([np.full_like(qb, j), qb, qc], axis=-1)
        if prev is None:
            value = np.ones_like(qb)
        else:
            value = bilinear(prev, np.stack([qb + vb, qc + vc], axis=-1)) * np.exp(-sigma * trilinear(dp, p + step))
            if levels:
                value = np.round(value * levels) / levels
        out[j] = prev = value
    return out


def _step_depth(dp: np.ndarray, plan: SlicePlan, sigma: float, k, p: np.ndarray) -> np.ndarray:
    """The optical depth of one step toward the sun from lateral points ``p`` (..., 2) on the k-th slice
    (ordinal ``k``, an int or an array like ``p[..., 0]``): ``sigma * L * (t1 - t0) * (rho(t0) + rho(t1)) / 2``
    over the part [t0, t1] of the step inside the box (half a step from the light-side slice)."""
    n, v = np.array(dp.shape[1:]), plan.lateral_step
    k = np.broadcast_to(np.asarray(k), p.shape[:-1])
    lo, hi = np.zeros(p.shape[:-1]), np.where(k == 0, 0.5, 1.0)
    for i in range(2):
        if v[i] != 0:
            t0, t1 = (-0.5 - p[..., i]) / v[i], (n[i] - 0.5 - p[..., i]) / v[i]
            lo, hi = np.maximum(lo, np.minimum(t0, t1)), np.minimum(hi, np.maximum(t0, t1))
        else:
            hi = np.where((p[..., i] >= -0.5) & (p[..., i] <= n[i] - 0.5), hi, -1.0)
    slice_at = np.asarray(plan.order)[np.clip(k, 0, plan.count - 1)]

    def rho(t):
        point = np.concatenate([(slice_at + t * plan.sign)[..., None], p + t[..., None] * v], axis=-1)
        return np.minimum(trilinear(dp, point), 1e37)
    with np.errstate(over="ignore", invalid="ignore"):
        add = sigma * (0.5 * rho(lo) + 0.5 * rho(hi)) * ((hi - lo) * plan.length)
    return np.where(hi > lo, add, 0.0)


def _columns(dp: np.ndarray, plan: SlicePlan, sigma: float) -> np.ndarray:
    """The true-path model (sun-aligned columns, see :func:`shear_warp_scheme`) on ``dp``."""
    n = np.array(dp.shape[1:])
    v = plan.lateral_step
    shift = plan.column_shift()
    kv = np.arange(plan.count, dtype=np.float32)[:, None] * v.astype(np.float32)[None, :]   # as the shader
    first, count = plan.column_range()
    q = np.stack(np.meshgrid(*(np.arange(f, f + m, dtype=np.float64) for f, m in zip(first, count)),
                             indexing="ij"), axis=-1)
    cells = np.stack(np.meshgrid(np.arange(n[0], dtype=np.float64), np.arange(n[1], dtype=np.float64),
                                 indexing="ij"), axis=-1)
    tau = np.zeros(q.shape[:-1])
    out = np.empty_like(dp)
    for k, j in enumerate(plan.order):
        tau = np.minimum(tau + _step_depth(dp, plan, sigma, k, q - k * v), TAU_MAX)
        # the warp: cell c of this slice from the columns c + shift - 1 .. c + shift + 2
        fr = kv[k].astype(np.float64) - shift[k]
        w = catmull_rom_weights(fr[0]), catmull_rom_weights(fr[1])
        taps = [np.arange(m)[:, None] + np.arange(-1, 3)[None, :] + shift[k, i] - first[i] for i, m in enumerate(n)]
        total = np.zeros(dp.shape[1:])
        low, high = np.full(total.shape, np.inf), np.full(total.shape, -np.inf)
        for tb in range(4):
            for tc in range(4):
                value = tau[np.ix_(taps[0][:, tb], taps[1][:, tc])]
                total += w[0][tb] * w[1][tc] * value
                if tb in (1, 2) and tc in (1, 2):
                    low, high = np.minimum(low, value), np.maximum(high, value)
        depth = np.clip(total, low, high)
        band = bends(n, v, k, kv[k] - shift[k].astype(np.float32))   # own rays there
        if band.any():
            start = cells[band]
            own = np.zeros(len(start))
            for back in range(k + 1):          # from the cell toward the sun, slice by slice
                own = np.minimum(own + _step_depth(dp, plan, sigma, k - back, start + back * v), TAU_MAX)
            depth[band] = own
        out[j] = np.exp(-np.maximum(depth, 0.0))
    return out


def bends(n, v, k: int, f) -> np.ndarray:
    """(n_b, n_c) bools: the cells of the k-th slice whose depth the warp cannot interpolate, so that
    they march their own ray: a tap (lateral ``c - 1 - f .. c + 2 - f``) lies beyond a face (along an axis
    with ``v != 0``; with ``v == 0`` those taps weigh 0), or the taps do not all leave the box toward the
    sun through the same face (the depth bends between them). A ray leaves through the light-side
    face after ``k + 0.5`` steps, through the sun-facing face of lateral axis i after ``(face - x) / v_i``.
    In float32, in the shader's order (``shear_warp.glsl bends``), so both take the same cells."""
    f32 = np.float32
    shape = (int(n[0]), int(n[1]))
    light_side = f32(k) + f32(0.5)
    low, high = [np.full(shape, f32(1e38)) for _ in range(2)], [np.full(shape, f32(1e38)) for _ in range(2)]
    beyond = np.zeros(shape, bool)
    for i in range(2):
        vi = f32(v[i])
        if vi == 0:
            continue
        c = np.arange(n[i], dtype=f32).reshape([-1 if a == i else 1 for a in range(2)])
        first, last = c - f32(1.0) - f32(f[i]), c + f32(2.0) - f32(f[i])
        beyond |= np.broadcast_to((first < f32(-0.5)) | (last > f32(n[i]) - f32(0.5)), shape)
        face = f32(n[i]) - f32(0.5) if vi > 0 else f32(-0.5)
        e0, e1 = (face - first) / vi, (face - last) / vi
        low[i], high[i] = np.broadcast_to(np.minimum(e0, e1), shape), np.broadcast_to(np.maximum(e0, e1), shape)
    one_face = light_side < np.minimum(low[0], low[1])
    for i in range(2):
        if f32(v[i]) != 0:
            one_face |= high[i] < np.minimum(light_side, low[1 - i])
    return beyond | ~one_face
