"""Froxel volumes: view-space grids whose W × H columns are the view rays through uv = ((x, y) + ½) / (W, H),
cut into D slices along the ray (``shaders/lib/froxel_slices.glsl``: even inside ``knee``, logarithmic
beyond, out to ``range``). Layer k of a (W, H, D + 1) volume holds what a medium gives from the camera to
slice boundary k (layer 0: the camera), and a pixel reads it trilinearly at its uv and the slice of its
distance (``froxel_read``). The volumetric fog and the light shafts march one; float64 twins here.
:class:`FroxelHistory` jitters where each slice is sampled and averages the frames through reprojection."""
from __future__ import annotations

import math
import struct

import numpy as np

from atmos.checks import num_field
from atmos.gpu.uniforms import write_block
from atmos.graph import TextureDesc, work_groups

KNEE_SHARE = 1.0 / 32.0      # the slices are nearly even inside range · KNEE_SHARE, logarithmic beyond
MAX_FROXELS = 256            # the most froxels along any axis


def froxel_knee(range_: float) -> float:
    """m: the knee of slices reaching ``range_`` m."""
    return float(range_) * KNEE_SHARE


def volume_desc(froxels, dtype: str = "f2") -> TextureDesc:
    """A (W, H, D + 1) RGBA storage volume for ``froxels`` = (W, H, D) slices (layer 0: the camera)."""
    w, h, d = froxels
    return TextureDesc((w, h, d + 1), components=4, dtype=dtype, storage=True)


def volume_image(frame, name: str):
    """The pass's froxel volume ``name`` as an image, its reads clamped to the edge texels (as
    :func:`froxel_lookup` reads)."""
    volume = frame.image(name)
    volume.repeat_x = volume.repeat_y = volume.repeat_z = False
    return volume


def froxel_distance(w, range_: float, knee: float):
    """Distance of slice coordinate w in [0, 1] (lib/froxel_slices.glsl)."""
    return knee * np.expm1(np.asarray(w, np.float64) * np.log1p(range_ / knee))


def froxel_w(d, range_: float, knee: float):
    """Slice coordinate in [0, 1] of distance d (lib/froxel_slices.glsl)."""
    return np.log1p(np.maximum(d, 0.0) / knee) / np.log1p(range_ / knee)


def column_rays(basis, w: int, h: int) -> tuple[np.ndarray, np.ndarray]:
    """(uv (W·H, 2), unit directions (W·H, 3)) of the columns, x fastest-varying last (index x·H + y);
    ``basis``: :func:`atmos.camera.view_basis`."""
    uv = np.stack(np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h, indexing="ij"), -1).reshape(-1, 2)
    rays = np.concatenate([uv * 2.0 - 1.0, np.ones((len(uv), 1))], 1) @ np.asarray(basis, np.float64).T
    return uv, rays / np.linalg.norm(rays, axis=-1, keepdims=True)


def froxel_lookup(volume: np.ndarray, uv, dist, range_: float, knee: float) -> np.ndarray:
    """(N, C): the trilinear read of ``volume`` (W, H, L, C) at uv (N, 2) and distance (N,) capped at
    ``range_`` (clamped to the edge texels, as the texture is): ``froxel_read`` of lib/froxel_slices.glsl."""
    w, h, layers = volume.shape[:3]
    uv = np.asarray(uv, np.float64)
    z = froxel_w(np.minimum(dist, range_), range_, knee) * (layers - 1)
    coords = [uv[:, 0] * w - 0.5, uv[:, 1] * h - 0.5, np.asarray(z, np.float64)]
    result = np.zeros((len(uv), volume.shape[3]))
    lows, fracs = [], []
    for c, n in zip(coords, (w, h, layers)):
        c = np.clip(c, 0.0, n - 1)
        lo = np.minimum(np.floor(c).astype(int), n - 2) if n > 1 else np.zeros(len(c), int)
        lows.append(lo)
        fracs.append(c - lo if n > 1 else np.zeros(len(c)))
    for corner in range(8):
        bits = [(corner >> i) & 1 for i in range(3)]
        weight = np.ones(len(uv))
        index = []
        for bit, lo, frac, n in zip(bits, lows, fracs, (w, h, layers)):
            weight = weight * (frac if bit else 1.0 - frac)
            index.append(np.minimum(lo + bit, n - 1))
        result += weight[:, None] * volume[index[0], index[1], index[2]]
    return result


# -- temporal accumulation ---------------------------------------------------------------------------
HISTORY_BLEND = 0.1          # the default least weight of a froxel volume's newest frame
GOLDEN_U32 = 2654435769      # 2^32 / phi: the slices' jitter runs as frac(1/2 + n / phi) (Roberts' R1 sequence)
HISTORY_BINDING = 1          # core/froxel_history.comp's History block, written once per resolve
_HISTORY_BLOCK = struct.Struct("<3f4x3f4x3f4x3f4fi")   # its std140 layout (80 bytes)


def history_field():
    """The ``froxel_history`` setting of an effect with a froxel volume (declared here once)."""
    return num_field(HISTORY_BLEND, 0.0, 1.0, "froxels: the least weight of the newest frame in the volume's "
                     "temporal accumulation (atmos.froxels.FroxelHistory: each slice sampled at a point that "
                     "moves every frame, the frames averaged through reprojection); 1: no history, every "
                     "slice sampled at its middle", lo_open=True)


def froxel_jitter(frame_index: int, jittered: bool = True) -> float:
    """Where in its slice a froxel volume samples in frame ``frame_index`` (lib/froxel_slices.glsl
    froxel_jitter): 0 its near boundary, 1 its far one; frac(1/2 + n / phi) in 32-bit fixed point (exact
    for any frame, the middle in frame 0), or the middle (0.5) where not ``jittered``."""
    if not jittered:
        return 0.5
    return ((((1 << 31) + int(frame_index) * GOLDEN_U32) % (1 << 32)) >> 8) / float(1 << 24)


def history_reference(fresh, history, basis, position, prev_basis, prev_position, range_: float, knee: float,
                      blend: float) -> np.ndarray:
    """float64 (W, H, L, C): ``shaders/core/froxel_history.comp`` — each boundary (x, y, k > 0) of ``fresh``
    (W, H, L, C) blended over ``history`` (the last output; None: none) read where its point was in the
    previous view (``prev_basis``, ``prev_position``), weight max(blend, moved / slice), 1 off that view."""
    fresh = np.asarray(fresh, np.float64)
    if history is None:
        return fresh.copy()
    w, h, layers = fresh.shape[:3]
    _, dirs = column_rays(basis, w, h)
    bounds = froxel_distance(np.arange(layers) / (layers - 1), range_, knee)
    moved = float(np.linalg.norm(np.asarray(position, np.float64) - np.asarray(prev_position, np.float64)))
    inverse = np.linalg.inv(np.asarray(prev_basis, np.float64))
    out = fresh.copy()
    for k in range(1, layers):
        p = np.asarray(position, np.float64) + dirs * bounds[k] - np.asarray(prev_position, np.float64)
        q = p @ inverse.T
        with np.errstate(divide="ignore", invalid="ignore"):
            uv = (q[:, :2] / q[:, 2:] + 1.0) * 0.5
        inside = (q[:, 2] > 0) & np.all((uv >= 0.0) & (uv <= 1.0), axis=1)
        if not inside.any():
            continue
        weight = max(blend, min(moved / max(bounds[k] - bounds[k - 1], 1e-6), 1.0))
        past = froxel_lookup(history, uv[inside], np.linalg.norm(p[inside], axis=1), range_, knee)
        column = out[:, :, k].reshape(w * h, -1)
        column[inside] = past + weight * (column[inside] - past)
        out[:, :, k] = column.reshape(w, h, -1)
    return out


class FroxelHistory:
    """A froxel volume's temporal accumulation (``shaders/core/froxel_history.comp``): the pass fills its
    transient volume with each slice sampled at :func:`froxel_jitter` (where :meth:`jittered`) and calls :meth:`resolve`, which blends it
    over the last output reprojected into this frame's view and returns the output to read (one of two
    3D textures kept across frames, freed by :meth:`release`). The newest frame weighs max(1 / (n + 1),
    ``blend``) after n frames (a running mean, then an exponential one); the history restarts when the
    volume's size, range or ``key`` (what the pass samples) changes, or a frame went by without a resolve."""

    def __init__(self, gpu):
        self.gpu = gpu
        self._volumes, self._current, self._state = None, 0, None
        self.frames = 0                 # frames the output averages (0: no history)

    def jittered(self, frame_index: int, blend: float) -> bool:
        """Whether the fill jitters its slices in frame ``frame_index`` (uniform ``froxel_jittered``): while the
        history goes on from the frame before with a ``blend`` below 1; where it restarts the fill samples the
        middles (a first or single frame is unbiased)."""
        return blend < 1.0 and self._state is not None and self._state[1] == frame_index - 1

    def resolve(self, frame, fresh, range_: float, knee: float, blend: float, key=()):
        """Blend ``fresh`` (a 3D texture the pass filled) over the history; return the resolved texture."""
        from atmos.camera import camera_matrices
        view = frame.view
        matrices = camera_matrices(view.camera, view.aspect)       # the frame's, computed once per frame
        size, index = fresh.size, view.clock.frame
        state = (size, range_, knee, key)
        if self._volumes is None or self._volumes[0].size != size:
            self._make(size)
        last = self._state
        if last is None or last[0] != state or last[1] != index - 1 or blend >= 1.0:
            self.frames = 0
        prev = matrices if last is None else last[2]
        p = self.gpu.program(compute_shader="core/froxel_history.comp")
        out = self._volumes[1 - self._current]
        a, b, c = prev.view_basis.T.tolist()      # std140: mat3 as three vec4 columns, vec3 + float, 4 scalars
        write_block(p, "History", HISTORY_BINDING, _HISTORY_BLOCK.pack(
            *a, *b, *c, *prev.camera_pos, math.dist(matrices.camera_pos, prev.camera_pos), range_, knee,
            max(1.0 / (self.frames + 1), blend), self.frames > 0))
        frame.dispatch(p, work_groups(size, (4, 4, 4)), textures={"fresh": fresh, "history": self._volumes[self._current]},
                       images={"resolved": out})
        self._current = 1 - self._current
        self._state = (state, index, matrices)
        self.frames += 1
        return out

    def read(self) -> np.ndarray:
        """float64 (W, H, L, 4): the last resolved volume (a GPU read, for tests and tools)."""
        if self._volumes is None or self._state is None:
            raise ValueError("FroxelHistory.read: nothing resolved yet (or released)")
        tex = self._volumes[self._current]
        w, h, d = tex.size
        return np.frombuffer(tex.read(), np.float16).reshape(d, h, w, 4).transpose(2, 1, 0, 3).astype(np.float64)

    def _make(self, size) -> None:
        self.release()
        ctx = self.gpu.ctx
        self._volumes = []
        for _ in range(2):
            tex = ctx.texture3d(size, 4, dtype="f2")       # read only once written (has_history)
            tex.repeat_x = tex.repeat_y = tex.repeat_z = False
            self._volumes.append(self.gpu.track(tex))
        self._current, self._state, self.frames = 0, None, 0

    def release(self) -> None:
        """Free the history (the next resolve makes it again)."""
        for tex in self._volumes or ():
            tex.release()
        self._volumes, self._state, self.frames = None, None, 0
