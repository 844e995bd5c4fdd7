"""Temporal reprojection of the ray-marched clouds: march 1 pixel of every r × r block per frame,
resolve the full-resolution image from this frame's samples and the reprojected history.

Each frame the march writes a low-res target whose texel (i, j) is the full-res pixel
(i·r + ox, j·r + oy), (ox, oy) = :func:`jitter` (frame, r). :meth:`TemporalClouds.resolve` then,
per full-res pixel (``shaders/clouds/raymarch/temporal.comp``, one compute invocation each):

* marched this frame → the fresh sample blended into the pixel's history (the same history as
  below, clamped to the box of this frame's 3×3 samples) with weight max(1/(n + 1), ``HISTORY_BLEND``),
  n the samples the history averages (a running mean, then an exponential one; the history stores n,
  carried times keep · (1 − moved) · (1 − drifting), so every rejection below restarts it and a
  moving camera takes the corrected fresh sample). With the march's jitter turning (:func:`jitter_shift`)
  a still picture converges to the mean over the offsets instead of freezing one offset's speckle;
* else the history, reprojected with the previous frame's camera: the ray's direction is projected
  first (sky at infinity), then the point at the distance the history holds there (camera + ray ·
  distance; where it holds no cloud, the scene's distance behind the pixel, so cloudless terrain
  moves with the terrain instead of staying put as sky would — the flight demo's 2-pixel stripes); clamped to the box of the current 3×3 low-res neighbourhood (``history_clamp``), the
  history first corrected by this frame's samples (the upsample's weights times fresh − history at
  each sample, reprojected with this pixel's motion: history and fresh samples agree, no 2-pixel
  pattern while moving), the clamp and the correction loosened to 0 below ``CLAMP_MOTION`` pixels of
  motion, so that a still camera over still clouds keeps every pixel's mean and converges to the
  full-res march in r² frames (without jitter; with it, toward the mean over the offsets), while
  clouds that move are clamped; rejected, falling back to the depth-aware upsample
  of this frame's samples (``lib/upsample.glsl``, shared with OffscreenLayer' composite), when its point was off screen or the scene behind the pixel changed
  (``DEPTH_TOLERANCE``: an object moved in front, or away); and mixed toward the upsample the faster
  the pixel moves (weight 1 − motion / ``motion_limit``, motion in full-res pixels per frame).
* under a camera still for r² frames (:func:`detects_change`: every pixel's last sample is then
  real, and marched with this camera) the history stays where the clouds evolve in place and is
  tested where they drift. The history also keeps each pixel's last marched sample (a fourth target;
  the upsample where the scene behind it changed), and drift is told from evolution by matching
  (``shaders/clouds/raymarch/drift.comp``, a low-res dispatch; twin :func:`.temporal_reference.drift_flags`):
  each low-res texel compares this frame's 3×3 samples with the samples marched at the same pixels r²
  frames ago, unshifted and shifted by one texel (r px) each way, on the frames whose jitter is the
  one of r² frames ago (:func:`jitter_repeats`; a new offset changes every sample by its noise). Where a shift explains the change
  better than none (by ``DRIFT_GAIN`` of it, the change above ``DRIFT_FLOOR``), or the samples changed
  by more than ``DRIFT_MEAN`` on average or one by more than ``DRIFT_CHANGE`` (a drift too fast for
  the shifts), the clouds moved: within one texel the block's fresh sample is compared with the
  history there, rejected (the upsample) where they differ by more than ``CHANGE_TOLERANCE`` (all of
  it from the tolerance, none below half; at 0.5–2 px/frame of drift stale history is worse than the
  upsample). Elsewhere the history stays: evolving clouds (sunset, bench_cloud_stability.py) change
  about half their samples by more than 2 % in r² frames, and the upsample there would be both wrong
  and flickering. Testing the history against itself everywhere fed on itself: a rejected block held
  the upsample, whose own error read as a change the next frame (7× the clouds' own change).

The output (premultiplied colour RGBA16F, (a·distance, a) RG32F as in :mod:`atmos.composition`) is
the next frame's history, stored as images; the same dispatch composites it onto "color" (and
"cloud_distance") in place for the pass, as a blend ONE, ONE_MINUS_SRC_ALPHA did. The history is no
graph resource: its binds ask for the barriers its reads need (:mod:`atmos.gpu.hazards`). The numpy
float64 reference is :mod:`.temporal_reference`.

Knobs and their cost (the resolve itself is one full-res dispatch: 1 fresh + 4 bilinear + 9
neighbourhood fetches of the low-res targets, 2 × 4 bilinear history fetches, 2 depth fetches, 1
last-sample fetch each pixel (the marched ones too: they blend into their history), plus 4 × 2 × 4
for the correction while moving: 1.43× the resolve without it, 640×360 r 2 on llvmpipe, measured as a
fragment pass; under a still camera also 9 drift-flag fetches, after the low-res drift dispatch: 25 +
9 × 9 fetches per low-res texel; 32 bytes of history per pixel, twice):

* ``reprojection`` (the plugin's): off → no history (the upsample alone, which blurs at r > 1);
  on → r² frames to converge when still, a ghost after fast motion bounded by the clamp.
* ``history_clamp`` (0..1, :data:`HISTORY_CLAMP`): how hard moving history is clamped to this
  frame's neighbourhood; 0 keeps it (sharpest, ghosts after motion), 1 removes ghosts but flickers
  thin features that the sparse samples miss. Free (the fetches are made for the upsample anyway).
* ``motion_limit`` (pixels per frame, :data:`MOTION_LIMIT`): history is dropped at this motion;
  smaller → less smear on fast turns, blurrier (upsampled) clouds while moving. Free.
"""
from __future__ import annotations

from operator import is_

import math
from functools import lru_cache

import moderngl
import numpy as np

from atmos.camera import camera_matrices, gl_matrix
from atmos.graph import work_groups
from atmos.offscreen import EDGE
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_images, bind_textures, std140_mat3, write_block, write_uniforms

RESOLUTIONS = (1, 2, 4)
RESOLVE_BLOCK, RESOLVE_BINDING, RESOLVE_SIZE = "Resolve", 1, 144   # temporal.comp's block of one resolve's camera and state
HISTORY_CLAMP = 1.0        # default clamp weight of moving history (0..1)
MOTION_LIMIT = 16.0        # default pixels of motion per frame at which history is dropped
CLAMP_MOTION = 1.0         # pixels of motion per frame below which the clamp is loosened linearly to 0 ...
HISTORY_BLEND = 0.15       # least weight of a fresh sample in a marched pixel's running mean (at most 1/0.15 samples)
GOLDEN = 0.6180339887498949   # the jitter's rotation per 2 r² frames (jitter_shift)
CHANGE_TOLERANCE = 0.02    # ... unless, where clouds drift, this frame's sample differs from the history by more
DRIFT_GAIN = 0.3           # still camera: the share of the r²-frame change a one-texel shift must explain to be drift ...
DRIFT_FLOOR = 0.1          # ... of a mean change (alpha, relative rgb) over the 3×3 samples above this ...
DRIFT_MEAN = 0.15          # ... or the mean change that is drift whatever the shift explains ...
DRIFT_CHANGE = 0.4         # ... as is this change of one sample
DEPTH_TOLERANCE = 0.1      # relative change of the scene distance behind a pixel that rejects its history
CUT_DISTANCE = 100.0       # m the camera moves in one frame that make a camera cut (history reset) ...
CUT_TURN = math.radians(30.0)   # ... or radians its view direction turns
ALPHA_EPS = 1e-4           # coverage below which a (a·d, a) pair holds no distance (sky at infinity)


def check_resolution(r) -> int:
    if r not in RESOLUTIONS or isinstance(r, bool):
        raise ValueError(f"the temporal resolve's resolution r must be 1, 2 or 4 (one pixel of every r x r "
                         f"block marched per frame), got {r!r}")
    return int(r)


def bayer(r: int) -> np.ndarray:
    """The r × r Bayer matrix ``b[y, x]`` (0 … r² − 1): consecutive values lie far apart."""
    b = np.zeros((1, 1), np.int64)
    while b.shape[0] < r:
        b = np.block([[4 * b, 4 * b + 2], [4 * b + 3, 4 * b + 1]])
    return b


def jitter(frame_index: int, r: int) -> tuple[int, int]:
    """The offset (ox, oy) in [0, r)² of the pixel marched in each r × r block at ``frame_index``:
    every r² frames visit all r² offsets, in Bayer order (each next one far from the last)."""
    r = check_resolution(r)
    if isinstance(frame_index, bool) or not isinstance(frame_index, (int, np.integer)) or frame_index < 0:
        raise ValueError(f"jitter's frame_index must be an integer >= 0, got {frame_index!r}")
    return _offsets(r)[int(frame_index) % (r * r)]


@lru_cache(maxsize=None)
def _offsets(r: int) -> tuple:
    """The r² offsets (ox, oy) in the order :func:`jitter` visits them (per frame: one lookup)."""
    b = bayer(r)
    return tuple((int(x), int(y)) for y, x in (np.argwhere(b == k)[0] for k in range(r * r)))


def jitter_shift(frame_index: int, r: int) -> float:
    """The march's rotation of its blue-noise first-sample offsets at ``frame_index`` (mod 1): the golden
    ratio times the pairs of r²-frame cycles done, so each pixel's samples (one a cycle) spread evenly
    over the step for the resolve to average, each offset twice in a row (:func:`jitter_repeats`)."""
    return math.fmod((int(frame_index) // (2 * r * r)) * GOLDEN, 1.0)


def jitter_repeats(frame_index: int, r: int) -> bool:
    """Whether ``frame_index`` marches with the offsets of r² frames before (the second cycle of a
    pair): only then does a still camera's change of a sample tell that the clouds drifted."""
    return (int(frame_index) // (r * r)) % 2 == 1


def low_size(size, r: int) -> tuple[int, int]:
    """The low-res target's (w, h) at resolution divisor r: every full-res pixel falls in one block."""
    return math.ceil(size[0] / r), math.ceil(size[1] / r)


def detects_change(still_frames: int, r: int, repeats: bool = True) -> bool:
    """Whether the resolve tells drifting clouds from evolving ones (the drift pass): once the camera
    has been still for r² frames, every pixel holds a sample marched with it, so a change is the
    clouds' where this frame's samples were marched with the same jitter as those (``repeats``,
    :func:`jitter_repeats`; a jitter that moved changes them by its noise)."""
    return still_frames >= r * r and repeats


def camera_state(camera, aspect: float) -> tuple:
    """What a camera's image depends on: two frames with the same state need no reprojection."""
    return (float(aspect), tuple(map(float, camera.position)), float(camera.yaw), float(camera.pitch),
            float(camera.roll), float(camera.fov_y), float(camera.near), float(camera.far))


def forward_of(camera) -> np.ndarray:
    """The unit view direction of ``camera`` (what :meth:`TemporalClouds.is_cut` compares)."""
    f = np.asarray(camera.forward(), np.float64)
    return f / max(math.hypot(*f), 1e-30)


class TemporalClouds:
    """Full-resolution cloud history of one pass on ``gpu``: ping-pong colour (RGBA16F), distance
    (RG32F, (a·d, a)), the scene distance behind each pixel (R32F) and its last sample (RGBA16F), the
    images the resolve stores, made (zeros) at the first resolve, remade (and so reset) when the size or
    r changes, kept across frames, freed by :meth:`release`.

    Per frame: ``offset = temporal.offset(r)`` (march with it), then :meth:`resolve`. The previous
    frame's camera is the one the last resolve was given (kept as a snapshot). The history resets by
    itself on a camera cut (:meth:`is_cut`: more than :data:`CUT_DISTANCE` m or :data:`CUT_TURN` in
    one frame) and when the size or r changes; :meth:`reset` forgets it by hand.
    """

    def __init__(self, gpu):
        self.gpu = gpu
        self.frame_index = 0
        self._sets: list | None = None     # [(color, distance, scene, last sample)] × 2
        self._drift = None                 # the low-res drift flags (r8)
        self._key = None                   # (size, r) the history was made for
        self._checked = None               # ((size, r), the textures resolve last checked for them; held)
        self._current = 0                  # which set holds the last output
        self._valid = False
        self._prev = None                  # (camera_state, CameraMatrices, position) of the last resolve
        self.still_frames = 0              # resolves in a row with the camera of the one before

    # -- per frame -----------------------------------------------------------------------------
    def offset(self, r: int) -> tuple[int, int]:
        """This frame's jitter offset (:func:`jitter` of the frame counter)."""
        return jitter(self.frame_index, r)

    @staticmethod
    def is_cut(camera, prev_position, prev_forward) -> bool:
        """Whether ``camera`` jumped since the last resolve: moved more than :data:`CUT_DISTANCE` m
        or turned its view more than :data:`CUT_TURN` (a teleport or a cut; reprojecting would smear)."""
        moved = math.dist(np.asarray(camera.position, np.float64), prev_position)
        cos = min(max(float(forward_of(camera) @ prev_forward), -1.0), 1.0)
        return not (moved <= CUT_DISTANCE and math.acos(cos) <= CUT_TURN)

    def reset(self) -> None:
        """Forget the history (a camera cut): the next resolve uses this frame's samples alone."""
        self._valid = False

    @staticmethod
    def _check_sizes(size, r: int, low_color, low_distance, depth, low_depth, onto, onto_distance) -> None:
        low = low_size(size, r)
        for name, tex in (("low_color", low_color), ("low_distance", low_distance)):
            if tuple(tex.size) != low:
                raise ValueError(f"TemporalClouds.resolve: {name} must be {low[0]}x{low[1]} (size {size} / {r}), "
                                 f"got {tex.size[0]}x{tex.size[1]}")
        if depth is not None and tuple(depth.size) != size:
            raise ValueError(f"TemporalClouds.resolve: depth must be {size[0]}x{size[1]}, got {depth.size}")
        if low_depth is not None and tuple(low_depth.size) != low:
            raise ValueError(f"TemporalClouds.resolve: low_depth must be {low[0]}x{low[1]}, got {low_depth.size}")
        for name, tex in (("onto", onto), ("onto_distance", onto_distance)):
            if tex is not None and tuple(tex.size) != size:
                raise ValueError(f"TemporalClouds.resolve: {name} must be {size[0]}x{size[1]}, got {tex.size}")

    def resolve(self, low_color, low_distance, size, r: int, offset, camera, aspect: float, depth=None,
                history_clamp: float = HISTORY_CLAMP, motion_limit: float = MOTION_LIMIT, low_depth=None,
                onto=None, onto_distance=None, repeats: bool = True, store_distance: bool = False):
        """Resolve this frame at full-res ``size`` (w, h) from the low-res ``low_color`` (RGBA
        premultiplied) and ``low_distance`` ((a·d, a)) textures marched at ``offset`` with divisor
        ``r``, seen by ``camera`` at ``aspect``; ``depth``: the scene's depth texture at ``size``
        (None: nothing but sky); ``low_depth``: the depth each sample's ray saw (low-res; with ``depth``
        the upsample is depth-aware, :data:`~atmos.offscreen.EDGE`). Returns (color, distance) full-res textures, valid until the next
        resolve (they are the history it reads). ``onto``: a full-res RGBA16F texture (the frame's
        colour) the same dispatch composites the result onto in place, premultiplied as
        :meth:`~atmos.graph.PassContext.blend_over` would; ``onto_distance`` (with ``onto``): an RG32F
        texture ("cloud_distance") the distance goes onto the same way (``store_distance``: stored instead,
        the pass being its first writer: what compositing onto a clear gives). ``repeats``: whether the samples
        were marched with the jitter of r² frames before (:func:`jitter_repeats`; False: no drift test)."""
        r = check_resolution(r)
        size = (int(size[0]), int(size[1]))
        ox, oy = offset
        if not (0 <= ox < r and 0 <= oy < r):
            raise ValueError(f"TemporalClouds.resolve: offset must lie in [0, {r})², got {offset!r}")
        textures = (low_color, low_distance, depth, low_depth, onto, onto_distance)
        if self._checked is None or self._checked[0] != (size, r) or not all(map(is_, self._checked[1], textures)):
            self._check_sizes(size, r, *textures)          # the textures a frame passes are checked when new
            self._checked = ((size, r), textures)
        if not 0.0 <= history_clamp <= 1.0 or not motion_limit > 0.0:
            raise ValueError(f"TemporalClouds.resolve: history_clamp must be in [0, 1] and motion_limit > 0, "
                             f"got {history_clamp!r}, {motion_limit!r}")
        if onto_distance is not None and onto is None:
            raise ValueError("TemporalClouds.resolve: onto_distance needs onto (the colour it composites with)")
        if self._key != (size, r):
            self._make(size, r)
        state = camera_state(camera, aspect)
        matrices = camera_matrices(camera, aspect)
        prev, write = self._sets[self._current], self._sets[1 - self._current]
        p = self.gpu.program(compute_shader="clouds/raymarch/temporal.comp",
                             defines={"COMPOSITE": int(onto is not None),
                                      "COMPOSITE_DISTANCE": (2 if store_distance else 1) if onto_distance is not None else 0})
        write_uniforms(p, r=r, has_depth=depth is not None,
                       edge=EDGE if depth is not None and low_depth is not None else 1e30)
        valid = self._valid and self._prev is not None and not self.is_cut(camera, self._prev[2], self._prev[3])
        detect = valid and state == self._prev[0] and detects_change(self.still_frames + 1, r, repeats)
        if detect:
            self._flag_drift(low_color, prev, r, (int(ox), int(oy)), depth, matrices, camera)
        block = np.zeros(RESOLVE_SIZE // 4, np.float32)
        block[0:12] = std140_mat3(matrices.gl("view_basis"))
        block[27], block[30] = camera.near, camera.far
        block.view(np.int32)[28:30] = (int(ox), int(oy))
        if valid:
            prev_state, prev_matrices, prev_position, _ = self._prev
            proj, view = prev_matrices.projection, prev_matrices.view
            block[12:24] = std140_mat3(gl_matrix(proj[[0, 1, 3], :3] @ view[:3, :3]))
            block[24:27] = np.asarray(camera.position, np.float64) - prev_position
            block[31:33] = history_clamp, motion_limit
            block.view(np.uint32)[33:36] = (1, int(state == prev_state), int(detect))
        write_block(p, RESOLVE_BLOCK, RESOLVE_BINDING, block.tobytes())
        bind_textures(p, low_color=low_color, low_distance=low_distance, hist_color=prev[0], hist_distance=prev[1],
                      hist_scene=prev[2], hist_sample=prev[3], drift=self._drift,               # drift: read when detect_change
                      low_depth=low_depth if low_depth is not None else low_color)     # low_depth: read at edge < 1e30
        if depth is not None:
            bind_textures(p, scene_depth=depth)
        bind_images(p, next_color=write[0], next_distance=write[1], next_scene=write[2], next_sample=write[3])
        if onto is not None:
            bind_images(p, color_image=onto, **({"distance_image": onto_distance} if onto_distance is not None else {}))
        dispatch(p, *work_groups(size, (8, 8)))   # the binds asked for the barriers; the stores are tracked
        self._current = 1 - self._current
        self.still_frames = self.still_frames + 1 if valid and state == self._prev[0] else 0
        self._valid = True
        self._prev = (state, matrices, np.array(camera.position, np.float64), forward_of(camera))
        self.frame_index += 1
        return write[0], write[1]

    def _flag_drift(self, low_color, prev, r: int, offset, depth, matrices, camera) -> None:
        """The low-res drift flags of this frame's samples against the last ones in the history set
        ``prev`` (``drift.comp``, one invocation per low-res texel); ``depth`` (or None: sky) tells
        where the scene changed."""
        p = self.gpu.program(compute_shader="clouds/raymarch/drift.comp")
        write_uniforms(p, r=r, offset=offset, has_depth=depth is not None, near=float(camera.near),
                       far=float(camera.far))
        if "view_basis" in p:
            p["view_basis"].write(matrices.gl("view_basis"))
        bind_textures(p, low_color=low_color, hist_sample=prev[3], hist_scene=prev[2])
        if depth is not None:
            bind_textures(p, scene_depth=depth)
        bind_images(p, flags=self._drift)
        dispatch(p, *work_groups(self._drift.size, (8, 8)))

    # -- lifetime ------------------------------------------------------------------------------
    def _make(self, size, r) -> None:
        self._free()
        ctx = self.gpu.ctx
        self._sets = []
        for _ in range(2):       # colour, distance, (scene distance, samples averaged), last sample: stored images
            self._sets.append(tuple(_zeros(ctx, self.gpu, size, n, dtype) for n, dtype in
                                    ((4, "f2"), (2, "f4"), (2, "f4"), (4, "f2"))))
        self._drift = _zeros(ctx, self.gpu, low_size(size, r), 1, "f1")
        self._key, self._current, self._valid = (size, r), 0, False

    def _free(self) -> None:
        for tex in [*(t for textures in self._sets or () for t in textures), *((self._drift,) if self._drift else ())]:
            tex.release()
        self._sets, self._drift, self._key, self._valid = None, None, None, False

    def release(self) -> None:
        """Free the history (the next resolve makes it again); the programs are the context's."""
        self._free()

    def read_history(self) -> tuple[np.ndarray, ...]:
        """The last output as float64 arrays, GL row order (row 0 at the bottom): colour (h, w, 4),
        distance (h, w, 2), scene distance (h, w) (−1: sky), each pixel's last marched sample (h, w, 4),
        the samples its colour averages (h, w). For tests and debugging (a GPU read)."""
        if self._sets is None:
            raise ValueError("TemporalClouds.read_history: nothing resolved yet (or released)")
        (w, h), _ = self._key
        color, distance, scene, last = self._sets[self._current]
        out = [np.frombuffer(t.read(), dt).reshape(h, w, n).astype(np.float64)
               for t, dt, n in ((color, np.float16, 4), (distance, np.float32, 2), (scene, np.float32, 2),
                                (last, np.float16, 4))]
        return out[0], out[1], out[2][..., 0], out[3], out[2][..., 1]

    @property
    def allocated(self) -> bool:
        """Whether history textures exist (tests: a culled pass allocates none)."""
        return self._sets is not None


def _zeros(ctx, gpu, size, components: int, dtype: str):
    """A new 2D texture of zeros (nearest, clamped; tracked by ``gpu``) for the resolve's images."""
    tex = ctx.texture(size, components, dtype=dtype)
    tex.write(bytes(size[0] * size[1] * components * int(dtype[1])))
    tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
    tex.repeat_x = tex.repeat_y = False
    return gpu.track(tex)
