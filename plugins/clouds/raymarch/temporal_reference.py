"""float64 numpy reference of the temporal resolve (:mod:`.temporal`, ``shaders/clouds/raymarch/temporal.comp``).

Arrays are in GL order: ``a[y, x]`` with row 0 at the bottom of the frame (texture order). It
projects with the previous camera's full 4×4 view-projection (the shader uses a translation-free
3×3 and the camera's offset: the same rays, written differently). :func:`resolve_reference` is one
frame; :class:`ReferenceHistory` keeps the history between frames like :class:`.temporal.TemporalClouds`.
"""
from __future__ import annotations

import numpy as np

from atmos.camera import Camera, view_basis

from atmos.offscreen import EDGE
from atmos.offscreen_reference import inv_depth, upsample_weights

from .temporal import (ALPHA_EPS, CHANGE_TOLERANCE, CLAMP_MOTION, DEPTH_TOLERANCE, DRIFT_CHANGE, DRIFT_FLOOR, DRIFT_GAIN, DRIFT_MEAN,
                       HISTORY_BLEND, HISTORY_CLAMP, MOTION_LIMIT, TemporalClouds, camera_state, detects_change, forward_of)


def bilinear(image: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
    """``image`` (h, w, c) at texel-centre coordinates (px, py) (texel (i, j) at (i, j)), clamped to the edge."""
    h, w = image.shape[:2]
    x0, y0 = np.floor(px), np.floor(py)
    fx, fy = (px - x0)[..., None], (py - y0)[..., None]
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)

    def at(x, y):
        return image[np.clip(y, 0, h - 1), np.clip(x, 0, w - 1)]

    return ((1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0))
            + fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1)))


def scene_distance(depth: np.ndarray | None, camera, aspect: float, size) -> np.ndarray:
    """Distance (m) from the camera to the scene behind each pixel, −1 where the depth is 1 (sky)."""
    w, h = size
    if depth is None:
        return -np.ones((h, w))
    rays = _rays(camera, aspect, size)
    z = camera.near / ((1.0 - depth) + depth * (camera.near / camera.far))
    return np.where(depth >= 1.0, -1.0, z * np.linalg.norm(rays, axis=-1))


def _rays(camera, aspect: float, size) -> np.ndarray:
    """(h, w, 3) view rays through the pixel centres, forward component 1 (lib/view_ray.glsl)."""
    w, h = size
    x = (np.arange(w) + 0.5) / w * 2 - 1
    y = (np.arange(h) + 0.5) / h * 2 - 1
    ndc = np.stack(np.broadcast_arrays(x[None, :], y[:, None], np.ones((h, w))), axis=-1)
    return ndc @ view_basis(camera, aspect).T


def _change(a: np.ndarray, b: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """The change measure of colours (..., 4): alpha, and rgb relative to ``scale``."""
    return np.maximum(np.abs(a[..., 3] - b[..., 3]), np.abs(a[..., :3] - b[..., :3]).max(axis=-1) / scale)


def _around(a: np.ndarray, i: int, j: int) -> np.ndarray:
    """``a`` (lh, lw, ...) at texel (x + i, y + j), clamped to the edge."""
    lh, lw = a.shape[:2]
    y, x = np.mgrid[0:lh, 0:lw]
    return a[np.clip(y + j, 0, lh - 1), np.clip(x + i, 0, lw - 1)]


def drift_flags(low_color: np.ndarray, last_sample: np.ndarray, r: int, offset, same=None) -> np.ndarray:
    """``shaders/clouds/raymarch/drift.comp``: per low-res texel (lh, lw), whether this frame's 3×3
    samples around it moved since they were last marched (``last_sample``, full-res (h, w, 4): each
    pixel's last sample, r² frames old at this frame's pixels): a one-texel shift explains
    ``DRIFT_GAIN`` of their change (above ``DRIFT_FLOOR`` each on average), or they changed by more
    than ``DRIFT_MEAN`` on average or one by more than ``DRIFT_CHANGE``; ``same`` (h, w): where the scene behind a pixel is the history's (None:
    everywhere), a sample elsewhere takes no part."""
    h, w = last_sample.shape[:2]
    lh, lw = low_color.shape[:2]
    ox, oy = offset
    rows, cols = np.minimum(np.arange(lh) * r + oy, h - 1), np.minimum(np.arange(lw) * r + ox, w - 1)
    before = last_sample[rows][:, cols]
    part = np.ones((lh, lw), bool) if same is None else same[rows][:, cols]
    scale = np.maximum(np.max([_around(low_color[..., :3].max(axis=-1), i, j) for j in range(-2, 3)
                               for i in range(-2, 3)], axis=0), 1e-3)
    costs, largest = [], None
    for uy in (-1, 0, 1):
        for ux in (-1, 0, 1):
            shifted = _around(before, ux, uy)
            # texel m of the patch is clamped first, then shifted (and clamped again), as the shader does
            changes = [_change(_around(low_color, i, j), _around(shifted, i, j), scale) * _around(part, i, j)
                       for j in (-1, 0, 1) for i in (-1, 0, 1)]
            costs.append(sum(changes))
            if ux == uy == 0:
                still, largest = costs[-1], np.max(changes, axis=0)
    best = np.min([c for k, c in enumerate(costs) if k != 4], axis=0)
    gain = (still - np.minimum(best, still)) / np.maximum(still, 1e-6)
    return ((gain > DRIFT_GAIN) & (still > 9 * DRIFT_FLOOR)) | (still > 9 * DRIFT_MEAN) | (largest > DRIFT_CHANGE)


def resolve_reference(history, low_color, low_distance, depth, size, r: int, offset, camera, prev, aspect: float,
                      history_clamp: float = HISTORY_CLAMP, motion_limit: float = MOTION_LIMIT,
                      detect_change: bool = False, low_depth=None):
    """One resolve at full-res ``size`` (w, h). ``history``: None (no valid history) or (color (h, w, 4),
    distance (h, w, 2), scene distance (h, w), each pixel's last marched sample (h, w, 4), the samples its
    colour averages (h, w)) of the previous frame; ``low_color`` (lh, lw, 4),
    ``low_distance`` (lh, lw, 2): this frame's samples at full-res pixels (i·r + ox, j·r + oy);
    ``depth``: the window-space scene depth (h, w) or None; ``prev``: (camera, aspect) of the
    history's frame; ``detect_change``: :func:`.temporal.detects_change` of the frames the camera
    has been still; ``low_depth``: the window depth each sample's ray saw (lh, lw), with ``depth``
    making the upsample depth-aware. Returns (color, distance, scene distance, last marched sample,
    samples averaged): the frame and the next history."""
    lh, lw = low_color.shape[:2]
    w, h = size
    ox, oy = offset
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    scene = scene_distance(depth, camera, aspect, size)

    # this frame's samples upsampled (bilinear in the low-res grid) and their 3x3 neighbourhood box
    lx, ly = (x - ox) / r, (y - oy) / r
    aware = depth is not None and low_depth is not None
    pixel_inv = inv_depth(depth if depth is not None else np.ones((h, w)), camera.near, camera.far)
    taps = upsample_weights(low_depth if aware else np.ones((lh, lw)), lx, ly, pixel_inv, camera.near, camera.far,
                            EDGE if aware else 1e30)
    both = np.concatenate([low_color, low_distance], axis=-1)
    up = sum(weight[..., None] * both[ty, tx] for tx, ty, weight in taps)
    cx = np.clip(np.floor(lx + 0.5), 0, lw - 1).astype(np.int64)
    cy = np.clip(np.floor(ly + 0.5), 0, lh - 1).astype(np.int64)
    neigh = np.stack([both[np.clip(cy + j, 0, lh - 1), np.clip(cx + i, 0, lw - 1)]
                      for j in (-1, 0, 1) for i in (-1, 0, 1)])
    lo, hi = neigh.min(axis=0), neigh.max(axis=0)

    fresh = ((x - ox) % r == 0) & ((y - oy) % r == 0)
    fi, fj = ((x - ox) // r).astype(np.int64), ((y - oy) // r).astype(np.int64)
    fresh_value = both[np.clip(fj, 0, lh - 1), np.clip(fi, 0, lw - 1)]
    out, last, held = up, up[..., :4], np.zeros((h, w))
    if history is not None:
        hist = np.concatenate([history[0], history[1]], axis=-1)
        prev_camera, prev_aspect = prev
        if camera_state(camera, aspect) == camera_state(prev_camera, prev_aspect):
            qx, qy, inside = x, y, np.ones((h, w), bool)
        else:
            qx, qy, inside = _reproject(history[1], camera, prev_camera, prev_aspect, aspect, size, scene)
        motion = np.hypot(qx - x, qy - y)
        sampled = bilinear(hist, qx, qy)
        # disocclusion: the scene behind this pixel is not the one the history saw there
        nx = np.clip(np.floor(qx + 0.5), 0, w - 1).astype(np.int64)
        ny = np.clip(np.floor(qy + 0.5), 0, h - 1).astype(np.int64)
        prev_scene = history[2][ny, nx]
        last = history[3][ny, nx]
        rays = _rays(camera, aspect, size)
        dirs = rays / np.linalg.norm(rays, axis=-1, keepdims=True)
        point = np.asarray(camera.position) + dirs * np.maximum(scene, 0)[..., None]
        expected = np.where(scene < 0, -1.0, np.linalg.norm(point - np.asarray(prev_camera.position), axis=-1))
        same = (expected < 0) == (prev_scene < 0)
        same &= (expected < 0) | (np.abs(prev_scene - expected) <= DEPTH_TOLERANCE * expected)
        last = np.where((inside & same)[..., None], last, up[..., :4])     # no last sample of this scene: the upsample
        # a still camera: where the clouds drift, has the image changed where it was marched? (the
        # nearest sample against the history there); where they evolve in place the history stays
        drifting = np.zeros((h, w))
        if detect_change:
            flags = drift_flags(low_color, history[3], r, offset, same=same).astype(np.float64)
            drifting = np.max([_around(flags, i, j)[cy, cx] for j in (-1, 0, 1) for i in (-1, 0, 1)], axis=0)
        fx = np.clip(np.floor(cx * r + ox + (qx - x) + 0.5), 0, w - 1).astype(np.int64)
        fy = np.clip(np.floor(cy * r + oy + (qy - y) + 0.5), 0, h - 1).astype(np.int64)
        predicted, now = history[0][fy, fx], low_color[cy, cx]
        change = drifting * _change(now, predicted, np.maximum(hi[..., :3].max(axis=-1), 1e-3))
        moved = np.maximum(np.minimum(motion / CLAMP_MOTION, 1.0), np.minimum(change / CHANGE_TOLERANCE, 1.0))[..., None]
        # the history corrected by this frame's samples: (fresh - history at the sample, moved like this pixel)
        correction = sum(weight[..., None] * (both[ty, tx] - bilinear(hist, tx * r + ox + (qx - x), ty * r + oy + (qy - y)))
                         for tx, ty, weight in taps)
        sampled = sampled + moved * correction
        clamp_w = np.where(fresh[..., None], history_clamp, history_clamp * moved)   # a marched pixel's mean: the box
        sampled = sampled + clamp_w * (np.clip(sampled, lo, hi) - sampled)
        sampled = np.clip(sampled, 0.0, [np.inf, np.inf, np.inf, 1.0, np.inf, 1.0])   # light, a.d >= 0; a in [0, 1]
        trust = 1.0 - np.clip(2.0 * change / CHANGE_TOLERANCE - 1.0, 0.0, 1.0)     # drifting clouds: the upsample
        keep = np.where(inside & same, trust * np.clip(1.0 - motion / motion_limit, 0.0, 1.0), 0.0)[..., None]
        out = out + keep * (sampled - out)
        held = history[4][ny, nx] * keep[..., 0] * (1.0 - moved[..., 0]) * (1.0 - drifting)   # the samples the history averages
        a = np.maximum(1.0 / (held + 1.0), HISTORY_BLEND)[..., None]
        # a marched pixel: the running mean of its samples, then an exponential one
        fresh_value = fresh_value + (1.0 - a) * (sampled - fresh_value)

    out = np.where(fresh[..., None], fresh_value, out)
    last = np.where(fresh[..., None], both[np.clip(fj, 0, lh - 1), np.clip(fi, 0, lw - 1), :4], last)
    held = np.where(fresh, np.minimum(held + 1.0, 1.0 / HISTORY_BLEND), held)
    return out[..., :4], out[..., 4:], scene, last, held


def _reproject(hist_distance, camera, prev_camera, prev_aspect, aspect, size, scene):
    """Where each pixel's cloud was in the previous frame (texel-centre coordinates) and whether it
    was on screen: first by direction (sky at infinity), then at the distance the history holds there,
    or where it holds no cloud at the ``scene`` distance (h, w) behind the pixel (−1: sky, stays at infinity)."""
    w, h = size
    rays = _rays(camera, aspect, size)
    dirs = rays / np.linalg.norm(rays, axis=-1, keepdims=True)
    vp = prev_camera.view_projection(prev_aspect)

    def project(v4):
        clip = v4 @ vp.T
        cw = clip[..., 3]
        safe = np.where(cw > 0, cw, 1.0)
        qx = (clip[..., 0] / safe * 0.5 + 0.5) * w - 0.5
        qy = (clip[..., 1] / safe * 0.5 + 0.5) * h - 0.5
        return qx, qy, cw > 0

    qx, qy, front = project(np.concatenate([dirs, np.zeros((h, w, 1))], axis=-1))
    ad = bilinear(hist_distance, qx, qy)
    cloud = ad[..., 1] > ALPHA_EPS
    d = np.where(cloud, ad[..., 0] / np.where(cloud, ad[..., 1], 1.0), scene)
    has = front & (d > 0)
    d = np.where(has, d, 0.0)
    points = np.asarray(camera.position) + dirs * d[..., None]
    px, py, pfront = project(np.concatenate([points, np.ones((h, w, 1))], axis=-1))
    qx, qy = np.where(has, px, qx), np.where(has, py, qy)
    front = np.where(has, pfront, front)
    inside = front & (qx >= -0.5) & (qx <= w - 0.5) & (qy >= -0.5) & (qy <= h - 0.5)
    return qx, qy, inside


class ReferenceHistory:
    """The reference's history across frames, reset like :class:`.temporal.TemporalClouds` (on a
    resolution change and a camera cut; ``history = None`` by hand)."""

    def __init__(self, size):
        self.size = tuple(size)
        self.history = self.prev = self.r = None
        self.still_frames = 0

    def resolve(self, low_color, low_distance, depth, r, offset, camera, aspect, repeats=True, **knobs):
        if r != self.r or (self.prev is not None and TemporalClouds.is_cut(camera, np.asarray(self.prev[0].position, np.float64),
                                                                           forward_of(self.prev[0]))):
            self.history, self.r = None, r
        still = self.history is not None and camera_state(camera, aspect) == camera_state(*self.prev)
        self.still_frames = self.still_frames + 1 if still else 0
        color, distance, scene, last, held = resolve_reference(self.history, low_color, low_distance, depth, self.size, r,
                                                   offset, camera, self.prev, aspect, **knobs,
                                                   detect_change=detects_change(self.still_frames, r, repeats))
        self.history = (color, distance, scene, last, held)
        self.prev = (_copy(camera), aspect)
        return color, distance


def _copy(camera):
    return Camera(position=np.array(camera.position), yaw=camera.yaw, pitch=camera.pitch, roll=camera.roll,
                  fov_y=camera.fov_y, near=camera.near, far=camera.far)
