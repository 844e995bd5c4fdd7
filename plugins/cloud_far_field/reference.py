"""numpy float64 reference of the far field's GPU cover measure (``cloud_far_field/cover.comp``)."""
from __future__ import annotations

import numpy as np

from atmos.plugins.clouds.edge import edge_weight
from atmos.plugins.cloud_shadows.reference import shifted


def volume_cover(sums_a, sums_b, t: float, a_shift, threshold: float, fade: float) -> float:
    """Edge-weighted covered fraction of the columns of mix(A, B, t); ``sums_a/b`` (nx, nz), A read at
    ``c + a_shift`` (zero past its edge)."""
    sums = (1.0 - t) * shifted(np.asarray(sums_a, np.float64), a_shift) + t * np.asarray(sums_b, np.float64)
    n = np.array(sums.shape)
    uv = np.stack(np.meshgrid(*((np.arange(m) + 0.5) / m for m in n), indexing="ij"), -1)
    w = edge_weight(uv, fade)
    return float((w * (sums > threshold)).sum() / max(w.sum(), 1e-30))


def column_quantiles(sums_a, sums_b, t: float, a_shift, fade: float, count: int = 33) -> np.ndarray:
    """(count,) edge-weighted quantiles 0 .. 1 of the column sums of mix(A, B, t) (``cover.comp``'s
    column_quantiles, which bins the sums into a histogram: within one bin of these): 0 inside the
    empty columns' share, else the weighted empirical distribution of the others, linear between them."""
    sums = (1.0 - t) * shifted(np.asarray(sums_a, np.float64), a_shift) + t * np.asarray(sums_b, np.float64)
    n = np.array(sums.shape)
    uv = np.stack(np.meshgrid(*((np.arange(m) + 0.5) / m for m in n), indexing="ij"), -1)
    w, s = np.round(edge_weight(uv, fade) * 1024.0).ravel(), sums.ravel()     # cover.comp's fixed point
    full = (s > 1e-6) & (w > 0)
    total, empty = w.sum(), w[(s <= 1e-6)].sum()
    order = np.argsort(s[full])
    values, cum = s[full][order], empty + np.cumsum(w[full][order])
    target = total * np.linspace(0.0, 1.0, count)
    out = np.interp(target, np.concatenate([[empty], cum]), np.concatenate([[0.0], values]))
    return np.where(target <= empty, 0.0, out) if total > 0 else np.zeros(count)


def field_fbm(xz, octaves, offsets, tile_size: float) -> np.ndarray:
    """The fbm (...,) of ``cloud_far_field/field.glsl`` at world ``xz`` (..., 2), mip 0: ``octaves`` the
    four downloaded textures (size, size, 4) [x, y, channel] (``OctaveTextures.download``), ``offsets``
    (4, 2) the drift in tiles; bilinear with repeat, texel i centred at (i + 0.5)/size."""
    from atmos.plugins.sky_layer.octaves import WEIGHTS
    xz = np.asarray(xz, np.float64)
    fbm = np.zeros(xz.shape[:-1])
    for w, tex, off in zip(WEIGHTS, octaves, np.asarray(offsets, np.float64)):
        plane = np.asarray(tex, np.float64)[..., 0]
        n = plane.shape[0]
        p = (xz / tile_size + off) * n - 0.5
        i0 = np.floor(p).astype(np.int64)
        f = p - i0
        at = lambda di, dk: plane[(i0[..., 0] + di) % n, (i0[..., 1] + dk) % n]
        fbm += w * ((1 - f[..., 0]) * (1 - f[..., 1]) * at(0, 0) + f[..., 0] * (1 - f[..., 1]) * at(1, 0)
                    + (1 - f[..., 0]) * f[..., 1] * at(0, 1) + f[..., 0] * f[..., 1] * at(1, 1))
    return fbm


def field_rank(fbm, quantiles) -> np.ndarray:
    """field.glsl's field_rank: the fraction of the layer's fbm at or below ``fbm`` (linear between the
    ``quantiles``, 0 below the first, 1 above the last)."""
    q = np.asarray(quantiles, np.float64)
    return np.interp(fbm, q, np.linspace(0.0, 1.0, len(q)))


def column_at_rank(rank, columns) -> np.ndarray:
    """field.glsl's far_quantile: the volume's column sum (cells) at ``rank`` (...,), linear between
    its ``columns`` quantiles (:func:`column_quantiles`)."""
    c = np.asarray(columns, np.float64)
    return np.interp(np.clip(rank, 0.0, 1.0), np.linspace(0.0, 1.0, len(c)), c)


MIN_SLANT = 0.1     # far.frag's horizon cap on the slant


def far_field_alpha(xz, dir_y, octaves, offsets, tile_size: float, quantiles, columns, column_tau: float,
                    thickness: float = 1.0) -> np.ndarray:
    """far.frag's opacity (...,) at world ``xz`` (..., 2) seen with view direction height ``dir_y``, mip 0,
    before the edge and horizon fades: vertical optical depth thickness · column_tau (sigma_t · cell
    height) · the volume's column sum at the point's rank, along the slant 1 / max(|dir_y|, MIN_SLANT)."""
    tau = far_optical_depth(xz, octaves, offsets, tile_size, quantiles, columns, float(thickness) * float(column_tau))
    return 1.0 - np.exp(-tau / np.maximum(np.abs(dir_y), MIN_SLANT))


def far_optical_depth(xz, octaves, offsets, tile_size: float, quantiles, columns, column_tau: float) -> np.ndarray:
    """The far field's vertical optical depth (...,) at world ``xz`` (..., 2), mip 0: ``column_tau`` (optical
    depth per summed cell) × the volume's column sum at the point's rank (far.frag's tau.x; the ground
    shadows' term beyond the volume, cloud_shadows/column.glsl)."""
    rank = field_rank(field_fbm(xz, octaves, offsets, tile_size), quantiles)
    return float(column_tau) * column_at_rank(rank, columns)
