"""float64 references of the physical camera's GPU work (``shaders/physical_camera``): the luminance
histogram, the metered and adapted EV100, the exposure it gives, and the bloom's mip chain.

Exposure (Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", sec. 5.1): the average luminance L
meters EV100 = log2(L · S / K) with S = 100, K = 12.5, and a camera at EV100 scales the scene by
1 / (1.2 · 2^EV100) (the saturation-based sensitivity), which puts the metered average at 1/9.6.
"""
from __future__ import annotations

import math

import numpy as np

BINS = 256                      # histogram bins: [0] below the range (and black), [1 .. BINS-1] over it
LUMA = (0.2126, 0.7152, 0.0722)  # Rec. 709 luminance of linear RGB
EV_OFFSET = math.log2(100.0 / 12.5)   # EV100 = log2(L) + EV_OFFSET (S = 100, K = 12.5)
DOWN = np.array([1.0, 5.0, 10.0, 10.0, 5.0, 1.0]) / 32.0     # bloom downsample taps 2i-2 .. 2i+3 per axis
UP_EVEN = np.array([5.0, 10.0, 1.0]) / 16.0                   # fine 2m: coarse m-1, m, m+1 (bilinear x tent)
UP_ODD = np.array([1.0, 10.0, 5.0]) / 16.0                    # fine 2m+1


def luminance(rgb) -> np.ndarray:
    """float64 luminance of linear RGB (..., >= 3)."""
    return np.asarray(rgb, np.float64)[..., :3] @ np.array(LUMA)


def ev100_of(lum) -> np.ndarray:
    """EV100 a luminance meters (-inf at 0)."""
    with np.errstate(divide="ignore"):
        return np.log2(np.asarray(lum, np.float64)) + EV_OFFSET


def exposure_of(ev100) -> np.ndarray:
    """The linear scale of a camera at ``ev100``: 1 / (1.2 · 2^EV100)."""
    return 1.0 / (1.2 * np.exp2(np.asarray(ev100, np.float64)))


def histogram_bins(lum, ev_range) -> np.ndarray:
    """Each luminance's bin: 0 below ``ev_range[0]`` (and for 0, NaN), else 1 + its EV100's place in
    (BINS - 1) equal bins over the range, values above it (+inf too) in the last."""
    lo, hi = ev_range
    ev = ev100_of(np.nan_to_num(np.asarray(lum, np.float64), nan=0.0))
    with np.errstate(invalid="ignore"):
        k = np.floor((ev - lo) / (hi - lo) * (BINS - 1))
    with np.errstate(invalid="ignore"):
        inside = ev >= lo                                        # False for 0 (-inf)
    return np.where(inside, 1 + np.clip(np.nan_to_num(k, nan=0.0, posinf=BINS), 0, BINS - 2), 0).astype(np.int64)


def histogram(rgb, ev_range) -> np.ndarray:
    """(BINS,) pixel counts of an image (..., >= 3) by :func:`histogram_bins`."""
    return np.bincount(histogram_bins(luminance(rgb), ev_range).ravel(), minlength=BINS)


def bin_centers(ev_range) -> np.ndarray:
    """(BINS,) EV100 each bin stands for: bin 0 the range's low end, bin k its middle."""
    lo, hi = ev_range
    width = (hi - lo) / (BINS - 1)
    return np.concatenate([[lo], lo + (np.arange(1, BINS) - 0.5) * width])


def metered_ev(counts, ev_range, metering_filter) -> float:
    """The mean EV100 of the pixels between the ``metering_filter`` (low, high) shares of the sorted
    luminances (a bin cut by a share counts by the part inside); the range's low end when none."""
    counts = np.asarray(counts, np.float64)
    total = counts.sum()
    a, b = metering_filter[0] * total, metering_filter[1] * total
    cum = np.cumsum(counts)
    w = np.clip(cum, a, b) - np.clip(cum - counts, a, b)
    if w.sum() <= 0.0:
        return float(ev_range[0])
    return float((w * bin_centers(ev_range)).sum() / w.sum())


def target_ev(mean_ev, compensation, ev_range) -> float:
    """The EV100 to adapt to: the metered one less the compensation (+1 EV: an image twice as bright),
    clamped to the range."""
    return float(np.clip(mean_ev - compensation, ev_range[0], ev_range[1]))


def adapt(ev, target, dt, speed_up, speed_down, transition) -> float:
    """One frame of adaptation from ``ev`` toward ``target`` over ``dt`` seconds: exponential with time
    constant ``transition`` / speed close to the target, at most ``speed`` EV per second (``speed_up``
    toward a higher EV, a brighter scene; ``speed_down`` toward a lower), never past the target."""
    delta = target - ev
    speed = speed_up if delta > 0.0 else speed_down
    step = min(speed * dt, abs(delta) * -math.expm1(-speed * dt / transition))
    return float(ev + math.copysign(step, delta))


def to_half(x) -> np.ndarray:
    """float64 of float16 rounding (an rgba16f image's store)."""
    return np.asarray(x, np.float64).astype(np.float16).astype(np.float64)


def _along(a: np.ndarray, axis: int, index: np.ndarray, weights: np.ndarray) -> np.ndarray:
    n = a.shape[axis]
    out = 0.0
    for t in range(index.shape[1]):
        out = out + np.take(a, np.clip(index[:, t], 0, n - 1), axis=axis) * _shape(weights[:, t], axis, a.ndim)
    return out


def _shape(w, axis, ndim):
    s = [1] * ndim
    s[axis] = -1
    return np.asarray(w, np.float64).reshape(s)


def down(a) -> np.ndarray:
    """One bloom downsample of an (h, w, c) image to ceil(h/2) x ceil(w/2): per axis the taps 2i-2 ..
    2i+3 (clamped to the edge) weighted by :data:`DOWN`."""
    a = np.asarray(a, np.float64)
    for axis in (0, 1):
        n = -(-a.shape[axis] // 2)
        i = np.arange(n)[:, None] * 2 + np.arange(-2, 4)[None, :]
        a = _along(a, axis, i, np.broadcast_to(DOWN, i.shape))
    return a


def up(coarse, shape) -> np.ndarray:
    """A coarse (h, w, c) image at the fine ``shape`` (H, W) (h = ceil(H/2)): per axis a 3x3 tent of
    bilinear samples, i.e. coarse m-1, m, m+1 by :data:`UP_EVEN` (fine 2m) or :data:`UP_ODD` (2m+1)."""
    a = np.asarray(coarse, np.float64)
    for axis, n in zip((0, 1), shape):
        i = np.arange(n)
        index = (i // 2)[:, None] + np.arange(-1, 2)[None, :]
        weights = np.where((i % 2 == 0)[:, None], UP_EVEN[None, :], UP_ODD[None, :])
        a = _along(a, axis, index, weights)
    return a


def bloom_chain(color, levels: int, half=True) -> np.ndarray:
    """The bloom (half-resolution (h, w, 3)) of an HDR ``color`` (H, W, >= 3): ``levels`` downsamples,
    then from the smallest up up_k = (down_k + up(up_{k+1})) / 2: level k weighs 2^-k (the smallest
    as much as the one above it), the weights sum to 1, so a flat image stays flat. ``half``: round
    each stored level to float16 as the GPU's images do."""
    store = to_half if half else (lambda x: x)
    chain = [np.asarray(color, np.float64)[..., :3]]
    for _ in range(levels):
        chain.append(store(down(chain[-1])))
    acc = chain[levels]
    for k in range(levels - 1, 0, -1):
        acc = store(0.5 * (chain[k] + up(acc, chain[k].shape[:2])))
    return acc


def present_input(color, bloom, weight) -> np.ndarray:
    """What the present tone-maps with the bloom on: mix(color, up(bloom), weight) (RGB)."""
    c = np.asarray(color, np.float64)[..., :3]
    return c + weight * (up(bloom, c.shape[:2]) - c)
