"""float64 reference of ``shaders/antialias/fxaa.frag`` on an (h, w, 4) image whose row 0 is the bottom
(the texture's own order)."""
from __future__ import annotations

import numpy as np

WEIGHTS = np.array([0.299, 0.587, 0.114])


def luma(rgb) -> np.ndarray:
    l = np.maximum(np.asarray(rgb, np.float64), 0.0) @ WEIGHTS
    return l / (1.0 + l)


def _fetch(img, x, y):
    h, w = img.shape[:2]
    return img[np.clip(y, 0, h - 1), np.clip(x, 0, w - 1)]


def _bilinear(img, px, py):
    qx, qy = px - 0.5, py - 0.5
    ix, iy = np.floor(qx).astype(np.int64), np.floor(qy).astype(np.int64)
    fx, fy = (qx - ix)[..., None], (qy - iy)[..., None]
    bottom = _fetch(img, ix, iy) * (1 - fx) + _fetch(img, ix + 1, iy) * fx
    top = _fetch(img, ix, iy + 1) * (1 - fx) + _fetch(img, ix + 1, iy + 1) * fx
    return bottom * (1 - fy) + top * fy


def fxaa(image, reduce_min: float, reduce_mul: float, span_max: float) -> np.ndarray:
    """The anti-aliased (h, w, 4) image (alpha kept)."""
    img = np.asarray(image, np.float64)
    h, w = img.shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    m = img[y, x]
    l_nw, l_ne = luma(_fetch(img, x - 1, y + 1)[..., :3]), luma(_fetch(img, x + 1, y + 1)[..., :3])
    l_sw, l_se = luma(_fetch(img, x - 1, y - 1)[..., :3]), luma(_fetch(img, x + 1, y - 1)[..., :3])
    l_m = luma(m[..., :3])
    dx, dy = -((l_nw + l_ne) - (l_sw + l_se)), (l_nw + l_sw) - (l_ne + l_se)
    reduce = np.maximum((l_nw + l_ne + l_sw + l_se) * 0.25 * reduce_mul, reduce_min)
    scale = 1.0 / (np.minimum(np.abs(dx), np.abs(dy)) + reduce)
    dx, dy = np.clip(dx * scale, -span_max, span_max), np.clip(dy * scale, -span_max, span_max)
    px, py = x + 0.5, y + 0.5

    def tap(t):
        return _bilinear(img, px + dx * t, py + dy * t)[..., :3]
    a = 0.5 * (tap(1 / 3 - 0.5) + tap(2 / 3 - 0.5))
    b = 0.5 * a + 0.25 * (tap(-0.5) + tap(0.5))
    l_min = np.minimum.reduce([l_m, l_nw, l_ne, l_sw, l_se])
    l_max = np.maximum.reduce([l_m, l_nw, l_ne, l_sw, l_se])
    l_b = luma(b)
    out = np.where(((l_b < l_min) | (l_b > l_max))[..., None], a, b)
    return np.concatenate([out, m[..., 3:]], -1)
