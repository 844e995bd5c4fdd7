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
