"""The shading grid: input checks, resolutions and the shear-warp's slice plan.

What the GPU shaders (:mod:`.shear_warp`, :mod:`.raymarch`, :mod:`.scattering`) and the float64
references (:mod:`.reference`) share: index space has voxel ``i`` centred at integer ``i``, the volume
is the box ``[-0.5, n-0.5]`` per axis; at ``scale`` s the same box has ceil(n / s) coarser cells.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

SCALES = (1, 2, 4)
MAJOR_ORDER = (1, 0, 2)          # ties for the slicing axis go to y, then x, then z
LATERAL = {0: (1, 2), 1: (0, 2), 2: (0, 1)}
TAU_MAX = 1e30                   # optical depth is clamped here: exp(-TAU_MAX) == 0, never inf - inf
SIGMA_MAX = 3.0e38               # largest sigma handed to float32 shaders


# -- input checks ----------------------------------------------------------------------------------
def check_density(density) -> np.ndarray:
    """``density`` as a float32 (nx, ny, nz) array, or a ValueError saying what is allowed."""
    try:
        array = np.asarray(density)
    except Exception:
        array = None
    if array is None or array.dtype.kind not in "fiu" or array.ndim != 3 or min(array.shape, default=0) < 1:
        what = "not an array" if array is None else f"dtype {array.dtype}, shape {array.shape}"
        raise ValueError(f"density must be a real-valued array of shape (nx, ny, nz), each >= 1 "
                         f"(y is height); got {what}")
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.ascontiguousarray(array, dtype=np.float32)
    bad = ~np.isfinite(out)
    if bad.any():
        raise ValueError(f"density must be finite (and within float32 range); {int(bad.sum())} value(s) are not, "
                         f"first at index {tuple(int(i) for i in np.argwhere(bad)[0])}")
    if (out < 0).any():
        raise ValueError(f"density must be >= 0; {int((out < 0).sum())} value(s) are negative "
                         f"(min {float(out.min())!r})")
    return out


def check_sigma(sigma) -> float:
    """``sigma`` as a float, or a ValueError (allowed: a finite real number >= 0)."""
    if isinstance(sigma, (bool, np.bool_)) or not isinstance(sigma, numbers.Real):
        raise ValueError(f"sigma must be a real number >= 0 (extinction per cell length at density 1); got {sigma!r}")
    value = float(sigma)
    if not math.isfinite(value) or value < 0:
        raise ValueError(f"sigma must be finite and >= 0 (extinction per cell length at density 1); got {sigma!r}")
    return value


def check_scale(scale) -> int:
    if isinstance(scale, (bool, np.bool_)) or not isinstance(scale, numbers.Integral) or int(scale) not in SCALES:
        raise ValueError(f"scale must be one of {SCALES} (full, half, quarter resolution); got {scale!r}")
    return int(scale)


# -- geometry --------------------------------------------------------------------------------------
def shading_shape(shape, scale: int) -> tuple[int, int, int]:
    """Shading grid for ``scale``: ceil(n / scale) per axis (the same box, coarser cells)."""
    return tuple(-(-int(n) // scale) for n in shape)


class SlicePlan:
    """How the shear-warp walks a grid of ``shape`` cells of size ``spacing`` (fine cells) for unit ``u``.

    ``axis`` slicing axis (largest |u/spacing|, ties y, x, z), ``lateral`` the other two,
    ``sign`` +1 when the sun is toward +axis, ``step`` the index-space step toward the sun
    (``step[axis] == sign``), ``length`` its length in fine cells, ``order`` the slices in order.
    """

    def __init__(self, shape, u: np.ndarray, spacing=(1.0, 1.0, 1.0)):
        self.shape = tuple(int(n) for n in shape)
        spacing = np.asarray(spacing, dtype=np.float64)
        w = u / spacing
        self.axis = max(MAJOR_ORDER, key=lambda a: (abs(w[a]), -MAJOR_ORDER.index(a)))
        self.lateral = LATERAL[self.axis]
        self.sign = 1 if w[self.axis] > 0 else -1
        self.step = w / abs(w[self.axis])
        self.step[self.axis] = float(self.sign)
        self.length = float(np.linalg.norm(spacing * self.step))
        n = self.shape[self.axis]
        self.order = list(range(n - 1, -1, -1)) if self.sign > 0 else list(range(n))

    @property
    def count(self) -> int:
        return len(self.order)

    # -- sun-aligned columns (the true-path shear-warp) ----------------------------------------------
    @property
    def lateral_step(self) -> np.ndarray:
        """``v``: the index-space step toward the sun along the two lateral axes, per slice."""
        return self.step[list(self.lateral)]

    def column_shift(self) -> np.ndarray:
        """(count, 2) ints: floor(k * v) for slice k (k-th in :attr:`order`), in float32 arithmetic as
        the shader works it out. Column Q lies at lateral ``Q - k v`` on slice k, so the cells of slice k
        take their depth from columns ``c + shift[k]`` (the tap at fraction ``k v - shift[k]``)."""
        v = self.lateral_step.astype(np.float32)
        return np.floor(np.arange(self.count, dtype=np.float32)[:, None] * v[None, :]).astype(np.int64)

    def column_range(self) -> tuple[np.ndarray, np.ndarray]:
        """(first column, column count) per lateral axis: every column a cell's bicubic taps (-1..+2
        around ``c + shift``) reach, with one more on each side (float32 rounding of ``k v``)."""
        shift = self.column_shift()
        n = np.array([self.shape[a] for a in self.lateral])
        first = shift.min(axis=0) - 2
        return first, shift.max(axis=0) + n + 2 - first + 1
