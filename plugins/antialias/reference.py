"""float64 reference of ``shaders/antialias/fxaa.comp`` on an (h, w, 4) image whose row 0 is the bottom
(the texture's own order)."""
from __future__ import annotations

import numpy as np

from atmos.glsl_math import catmull_rom_weights
from atmos.render_core import MOTION_DEPTH_TOLERANCE

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


# -- temporal anti-aliasing (shaders/antialias/taa_resolve.comp) --------------------------------------
TAA_LUMA = np.array([0.2126, 0.7152, 0.0722])
TAA_MOTION_GAIN = 0.2          # taa_resolve.comp's MOTION_GAIN: the newest frame's weight per pixel moved
TAA_MOTION_DEPTH = MOTION_DEPTH_TOLERANCE    # taa_resolve.comp's: a motion's depth tag against the depth buffer


def catmull_rom(img, px, py) -> np.ndarray:
    """``img`` (h, w, c) at pixel coordinates (px, py) by Catmull-Rom over the 4x4 nearest texels, clamped
    to the edge (taa_resolve.comp history_at)."""
    tx, ty = np.asarray(px, np.float64) - 0.5, np.asarray(py, np.float64) - 0.5
    ix, iy = np.floor(tx).astype(np.int64), np.floor(ty).astype(np.int64)
    wx, wy = catmull_rom_weights(tx - ix), catmull_rom_weights(ty - iy)
    out = 0.0
    for j in range(4):
        for i in range(4):
            out = out + (wx[i] * wy[j])[..., None] * _fetch(img, ix + i - 1, iy + j - 1)
    return out


def taa_resolve(color, depth, history, basis, position, near: float, far: float, prev_view_proj,
                blend: float, motion=None) -> np.ndarray:
    """float64 (h, w, 4) of taa_resolve.comp: ``color`` (h, w, 4) and window ``depth`` (h, w) of this frame
    (row 0 at the bottom) seen through ``basis`` (atmos.camera.view_basis) from ``position``; ``history``
    (h, w, 4) the last output or None; ``prev_view_proj`` the previous frame's 4×4 view_proj; ``motion``
    (h, w, 4) the motion target (world motion, depth tag) or None (the shader without MOTION)."""
    color = np.asarray(color, np.float64)
    h, w = color.shape[:2]
    out = color.copy()
    if history is None:
        return out
    ys, xs = np.mgrid[0:h, 0:w]
    pad = np.pad(color[..., :3], ((1, 1), (1, 1), (0, 0)), mode="edge")
    dpad = np.pad(np.asarray(depth, np.float64), 1, mode="edge")
    stack = np.stack([pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
    lo, hi = stack.min(axis=0), stack.max(axis=0)
    offsets = [(0, 0)] + [(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1)]    # the pixel first: ties keep it
    depths = np.stack([dpad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy, dx in offsets])
    pick = np.argmin(depths, axis=0)
    d = np.take_along_axis(depths, pick[None], 0)[0]
    uv = np.stack([(xs + 0.5) / w, (ys + 0.5) / h], -1)
    ray = np.concatenate([uv * 2.0 - 1.0, np.ones((h, w, 1))], -1) @ np.asarray(basis, np.float64).T
    with np.errstate(divide="ignore"):
        z = near / ((1.0 - d) + d * (near / far))
    point = np.where((d < 1.0)[..., None], np.asarray(position, np.float64) + z[..., None] * ray, ray)
    if motion is not None:
        dy, dx = np.array(offsets).T
        qy, qx = np.clip(ys + dy[pick], 0, h - 1), np.clip(xs + dx[pick], 0, w - 1)
        m = np.asarray(motion, np.float64)[qy, qx]
        tagged = (np.abs(m[..., 3] - d) <= TAA_MOTION_DEPTH) & (d < 1.0)
        point = point - np.where(tagged[..., None], m[..., :3], 0.0)
    clip = np.concatenate([point, (d < 1.0).astype(np.float64)[..., None]], -1) @ np.asarray(prev_view_proj, np.float64).T
    valid = clip[..., 3] > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        prev = clip[..., :2] / clip[..., 3:] * 0.5 + 0.5
    valid &= np.all((prev >= 0.0) & (prev <= 1.0), axis=-1)
    prev = np.where(valid[..., None], prev, 0.5)
    past = np.clip(catmull_rom(np.asarray(history, np.float64)[..., :3], prev[..., 0] * w, prev[..., 1] * h), lo, hi)
    now = color[..., :3]
    moved = np.hypot(prev[..., 0] * w - (xs + 0.5), prev[..., 1] * h - (ys + 0.5))
    a = np.maximum(blend, np.minimum(moved * TAA_MOTION_GAIN, 1.0))
    wn = a / (1.0 + now @ TAA_LUMA)
    wp = (1.0 - a) / (1.0 + past @ TAA_LUMA)
    blended = (now * wn[..., None] + past * wp[..., None]) / (wn + wp)[..., None]
    out[..., :3] = np.where(valid[..., None], blended, now)
    return out
