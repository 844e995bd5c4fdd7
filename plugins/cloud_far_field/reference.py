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


def far_field_density(xz, octaves, offsets, tile_size: float, quantiles, cover: float, softness: float) -> np.ndarray:
    """d.x (...,) of ``cloud_far_field/field.glsl`` at world ``xz`` (..., 2), mip 0: ``octaves`` the four
    downloaded textures (size, size, 4) [x, y, channel] (``OctaveTextures.download``), ``offsets`` (4, 2)
    the drift in tiles; bilinear with repeat, texel i centred at (i + 0.5)/size."""
    from atmos.plugins.cloud_far_field.cover import emptiness
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
    e = emptiness(quantiles, cover)
    return (np.clip(fbm, e, e + softness) - e) / softness
