"""Dobashi's cloud cellular automaton (thesis sec. 2.3, eq. 2.1–2.10) on the GPU with compute shaders.

One :meth:`CloudAutomaton.step` = growth (eq. 2.1–2.4) → stochastic rules (eq. 2.5–2.7) →
advection (eq. 2.8–2.10), one compute dispatch (each result word steps its advected source words;
the random streams' keys are hashed on the GPU from the seed and the step); steps chain without a
CPU round trip.

Growth neighbourhood f_act (eq. 2.4, whose vertical axis k is our height axis y): the OR of act at
``(x±1, y, z)``, ``(x, y±1, z)``, ``(x, y, z±1)``, ``(x±2, y, z)``, ``(x, y, z±2)`` and
``(x, y−2, z)`` — 11 cells; there is no ``y+2`` term, so clouds grow upward. Cells outside the
volume count as inactive.

Stochastic rules: ``cld &= ~(U_ext < T(p_ext))``, ``hum |= U_hum < T(p_hum)``,
``act |= U_act < T(p_act)``, where ``T(p) = floor(p * 2**16 + 0.5)`` and ``U`` is a 16-bit uniform
random number per cell, rule and step (16 bits of precision: an event has probability
``T / 65536``, within 2**-17 of p; p = 0 never and p = 1 always fires). ``U``'s bit j of cell x
is bit ``x % 32`` of a counter-based hash (:mod:`atmos.hashing`) of the cell's 32-cell word
index ``x // 32 + nwx * (y + ny * z)`` in the stream ``(seed, step_count, rule, j)``.

Layouts:

* ``"packed"`` — 32 cells per uint32 word along x (x padded to ``32 * nwx``, padding bits always 0);
  one invocation updates one word with bit operations. The Bernoulli masks are built bit-sliced:
  ``U < T`` is decided MSB first, one 32-bit hash word (32 cells) per bit plane, until every cell
  of interest is decided (≈ log2(32) + 2 planes on average instead of 32 per-cell hashes).
  Per-cell probability arrays are quantized to ``T`` on the GPU (exact in float32) and stored as 17
  threshold bit planes per rule, so scalar and array probabilities take the same path.
* ``"cell"`` — one uint per cell (bit 0 hum, bit 1 act, bit 2 cld), the thesis's one-texel-per-cell
  layout, as a baseline. It reads the same hash words and takes its bit, so both layouts produce
  identical states.

GPU-side state for the later stages (smoothing, rendering): :attr:`CloudAutomaton.state_buffer`,
a ``moderngl.Buffer`` that holds the current state (it alternates between two buffers; read the
property after each step). Its layout:

* packed: ``uint32[3 * N]`` with ``N = nwx * ny * nz``; field f (0 hum, 1 act, 2 cld) of word
  ``w = wx + nwx * (y + ny * z)`` at ``[f * N + w]``; cell ``x = 32 * wx + b`` is bit b.
* cell: ``uint32[nx * ny * nz]``; cell ``c = x + nx * (y + ny * z)``; bit 0 hum, 1 act, 2 cld.

After :meth:`step` returns, a memory barrier has been issued, so later shaders and buffer reads see
the new state.
"""
from __future__ import annotations

import math
import numbers

import moderngl
import numpy as np

from atmos.checks import check_shape, is_int
from atmos.gpu.context import GpuContext, require_gpu
from atmos.gpu.uniforms import bind_buffers, bind_textures, write_uniforms
from atmos.gpu.hazards import dispatch

PRECISION_BITS = 16
MAX_LAYERS = 128        # layers (ny) the advection takes shifts for (common.glsl: a uniform array)
PLANES = PRECISION_BITS + 1
LAYOUTS = ("packed", "cell")
RULES = ("p_ext", "p_hum", "p_act")
_GROUP = 64
_ONE = 1 << PRECISION_BITS

_NO_SHIFTS = bytes(8 * MAX_LAYERS)     # u_shifts of a step that does not advect


def _mb(n: int) -> str:
    return f"{n / 2**20:.1f} MiB"


class CloudAutomaton:
    """Cloud cellular automaton of ``shape = (nx, ny, nz)`` cells (y is height) on a GpuContext ``gpu``.

    ``seed`` (an int in [0, 2**32)) selects the random streams; ``layout`` is ``"packed"`` (32
    cells per uint32 word, the fast one) or ``"cell"`` (one uint per cell, the thesis's layout).
    Both give bit-identical results, equal to :func:`atmos.plugins.clouds.automaton.reference.step`. The programs
    come from ``gpu.program`` (shared by every automaton on the context, released by the context);
    :meth:`release` frees the buffers.
    """

    def __init__(self, gpu: GpuContext, shape, seed: int = 0, layout: str = "packed"):
        ctx = require_gpu(gpu).ctx
        if layout not in LAYOUTS:
            raise ValueError(f"layout must be one of {LAYOUTS}, got {layout!r}")
        if not is_int(seed) or not 0 <= int(seed) < 2**32:
            raise ValueError(f"seed must be an int in [0, 2**32), got {seed!r}")
        shape = check_shape(shape)
        nx, ny, nz = shape
        nwx = -(-nx // 32)
        words = nwx * ny * nz
        cells = nx * ny * nz
        count = words if layout == "packed" else cells
        needs = {"the probability array": 4 * cells}
        if layout == "packed":
            needs["the packed state"] = 3 * 4 * words
            needs["the threshold bit planes"] = PLANES * 4 * words
        else:
            needs["the cell state"] = 4 * cells
        limit = int(ctx.info.get("GL_MAX_SHADER_STORAGE_BLOCK_SIZE", 2**27))
        what, biggest = max(needs.items(), key=lambda kv: kv[1])
        if biggest > limit:
            raise ValueError(
                f"shape {shape} is too big for this GPU with layout {layout!r}: {what} needs "
                f"{_mb(biggest)}, but a shader storage block holds at most {_mb(limit)} "
                f"(GL_MAX_SHADER_STORAGE_BLOCK_SIZE); use a smaller shape"
                + (" or layout='packed'" if layout == "cell" else ""))
        if ny > MAX_LAYERS:
            raise ValueError(f"shape {shape} has {ny} layers; the automaton advects at most {MAX_LAYERS} (ny <= {MAX_LAYERS})")
        max_groups = ctx.info.get("GL_MAX_COMPUTE_WORK_GROUP_COUNT", (65535, 65535, 65535))
        groups = -(-count // _GROUP)
        gx = min(groups, int(max_groups[0]))
        gy = -(-groups // gx)
        if count >= 2**32 or gy > int(max_groups[1]):
            raise ValueError(f"shape {shape} has too many cells for one compute dispatch on this GPU; "
                             f"use a smaller shape")

        self.gpu = gpu
        self.ctx = ctx
        self.shape = shape
        self.layout = layout
        self.seed = int(seed)
        self.step_count = 0
        self.words_x = nwx
        self._count = count
        self._cells = cells
        self._grid = (gx, gy, 1)
        self._released = False
        self._last_mask = (1 << (nx - 32 * (nwx - 1))) - 1 if nx % 32 else 0xFFFFFFFF

        prefix = "clouds/automaton/packed_" if layout == "packed" else "clouds/automaton/cell_"
        self._prog_step = gpu.program(compute_shader=prefix + "step.comp")
        self._prog_pack = (gpu.program(compute_shader="clouds/automaton/pack_thresholds.comp")
                           if layout == "packed" else None)
        objects = []
        try:
            state_bytes = needs["the packed state" if layout == "packed" else "the cell state"]
            self._state = [ctx.buffer(reserve=state_bytes), ctx.buffer(reserve=state_bytes)]
            objects += self._state
            for buf in self._state:
                buf.clear()
            self._current = 0
            self._shifts = self._shift_bytes = None   # the advection's last shifts and their uniform bytes
            self._dummy = ctx.buffer(reserve=16)
            objects.append(self._dummy)
        except Exception:
            for obj in objects:
                obj.release()
            raise
        # Per-rule probability storage, made on first use of an array: packed -> threshold planes
        # (plus one shared float staging buffer), cell -> float buffers read by the step shader.
        self._prob_buffers: list = [None, None, None]
        self._staging = None
        self._prob_cache: list = [None, None, None]   # the array last uploaded per rule (identity)
        self._prog_texture = None                      # made on the first step_with_texture
        self._words = words

    # -- public API ----------------------------------------------------------------------------
    @property
    def state_buffer(self) -> moderngl.Buffer:
        """The buffer holding the current state (layout in the module docstring); changes per step."""
        self._check_alive()
        return self._state[self._current]

    def upload(self, hum, act, cld) -> None:
        """Replace the state with bool arrays of shape ``(nx, ny, nz)``."""
        self._check_alive()
        fields = [self._check_bool(name, a) for name, a in (("hum", hum), ("act", act), ("cld", cld))]
        if self.layout == "packed":
            data = np.concatenate([self._pack(a).ravel() for a in fields])
        else:
            hum, act, cld = (a.transpose(2, 1, 0).astype(np.uint32) for a in fields)
            data = hum | (act << np.uint32(1)) | (cld << np.uint32(2))
        self._state[self._current].write(np.ascontiguousarray(data, dtype="<u4").tobytes())

    def download(self):
        """The current state as bool arrays ``(hum, act, cld)`` of shape ``(nx, ny, nz)``."""
        self._check_alive()
        raw = np.frombuffer(self._state[self._current].read(), dtype="<u4")
        nx, ny, nz = self.shape
        if self.layout == "packed":
            words = raw.reshape(3, nz, ny, self.words_x)
            bits = np.unpackbits(words.view(np.uint8), axis=-1, bitorder="little")[..., :nx]
            return tuple(np.ascontiguousarray(bits[f].transpose(2, 1, 0).astype(bool)) for f in range(3))
        cells = raw.reshape(nz, ny, nx).transpose(2, 1, 0)
        return tuple(np.ascontiguousarray((cells >> np.uint32(f)) & np.uint32(1)).astype(bool)
                     for f in range(3))

    def step(self, p_ext=0.0, p_hum=0.0, p_act=0.0, shift=(0, 0)) -> None:
        """One step: growth → stochastic rules → advection by ``shift`` (see the module docstring).

        ``p_*`` are floats in [0, 1] or float32 arrays of shape ``(nx, ny, nz)`` with values in
        [0, 1]. Arrays are uploaded once and cached by identity: passing the same array object again
        costs nothing, so do not modify a passed array in place (pass a new array, or call
        :meth:`forget_probabilities`). ``shift`` is ``(sx, sz)`` or an int array of shape
        ``(ny, 2)`` (one pair per height layer): contents move by +sx along x and +sz along z.
        Everything is checked before any GPU state changes.
        """
        self._check_alive()
        probs = [self._check_probability(name, p) for name, p in zip(RULES, (p_ext, p_hum, p_act))]
        shifts = self._check_shift(shift)

        modes, thresholds = [], []
        for rule, (kind, value) in enumerate(probs):
            if kind == "array":
                self._upload_probability(rule, value)
                modes.append(2)
                thresholds.append(0)
            else:
                modes.append(0 if value == 0 else 1)
                thresholds.append(value)
        self._run_step(modes, thresholds, shifts)

    def _run_step(self, modes, thresholds, shifts) -> None:
        """Dispatch growth + stochastic rules (``modes``: 0 off, 1 scalar, 2 per-cell) + advection, one dispatch."""
        if not shifts.any():
            shift_bytes = _NO_SHIFTS
        else:
            if not np.array_equal(shifts, self._shifts):
                self._shifts = shifts
                padded = np.zeros((MAX_LAYERS, 2), "<i4")
                padded[: len(shifts)] = shifts
                self._shift_bytes = padded.tobytes()
            shift_bytes = self._shift_bytes
        prog = self._prog_step
        self._set_grid(prog)        # the program is shared by every automaton on the context: set per run
        write_uniforms(prog, u_mode=tuple(modes), u_threshold=tuple(thresholds), u_seed=self.seed,
                       u_step=self.step_count & 0xFFFFFFFF, u_shifts=shift_bytes)
        src, dst = self._state[self._current], self._state[1 - self._current]
        per_cell = "Prob" if self.layout == "cell" else "Planes"     # the step's probability blocks, by rule
        bind_buffers(prog, {f"{per_cell}{name}": self._prob_buffers[rule] if modes[rule] == 2 else self._dummy
                            for rule, name in enumerate(("Ext", "Hum", "Act"))}, Src=src, Dst=dst)
        dispatch(prog, *self._grid)
        self._current = 1 - self._current
        self.step_count += 1

    def forget_probabilities(self) -> None:
        """Drop the identity cache of probability arrays (after modifying one in place)."""
        self._prob_cache = [None, None, None]

    def release(self) -> None:
        """Free the GPU objects; the automaton cannot be used afterwards."""
        if self._released:
            return
        self._released = True
        objects = [self._dummy, self._staging, *self._state, *self._prob_buffers]
        for obj in objects:
            if obj is not None:
                obj.release()
        self._prob_cache = [None, None, None]

    def __repr__(self) -> str:
        return (f"CloudAutomaton(shape={self.shape}, seed={self.seed}, layout={self.layout!r}, "
                f"step_count={self.step_count})")

    # -- internals -----------------------------------------------------------------------------

    def _set_grid(self, prog, count: int | None = None) -> None:
        """This automaton's size uniforms (the programs are shared with other automata: set before each run)."""
        write_uniforms(prog, u_size=self.shape, u_nwx=self.words_x,
                       u_count=self._count if count is None else count, u_last_mask=self._last_mask)

    def _check_alive(self) -> None:
        if self._released:
            raise RuntimeError("this CloudAutomaton was released")

    def _check_bool(self, name: str, a) -> np.ndarray:
        if not isinstance(a, np.ndarray) or a.dtype != np.bool_:
            kind = f"dtype {a.dtype}" if isinstance(a, np.ndarray) else type(a).__name__
            raise ValueError(f"{name} must be a numpy bool array of shape {self.shape}, got {kind}")
        if a.shape != self.shape:
            raise ValueError(f"{name} must have shape {self.shape} (nx, ny, nz), got {a.shape}")
        return a

    def _pack(self, a: np.ndarray) -> np.ndarray:
        """bool [x, y, z] -> uint32 words [z, y, wx] (bit b of word wx = cell 32 * wx + b)."""
        nx, ny, nz = self.shape
        padded = np.zeros((nz, ny, 32 * self.words_x), dtype=bool)
        padded[:, :, :nx] = a.transpose(2, 1, 0)
        return np.packbits(padded, axis=-1, bitorder="little").view("<u4")

    def _check_probability(self, name: str, p):
        """('scalar', threshold) or ('array', float32 array); ValueError naming what is allowed."""
        allowed = f"a float in [0, 1] or a float32 array of shape {self.shape} with values in [0, 1]"
        if isinstance(p, np.ndarray) and p.ndim > 0:
            if p.dtype != np.float32:
                raise ValueError(f"{name} must be {allowed}; got an array of dtype {p.dtype} "
                                 f"(convert with .astype(numpy.float32))")
            if p.shape != self.shape:
                raise ValueError(f"{name} must be {allowed}; got an array of shape {p.shape}")
            if p is self._prob_cache[RULES.index(name)]:
                return "array", p
            if not np.isfinite(p).all():
                raise ValueError(f"{name} must be {allowed}; the array holds NaN or infinite values")
            lo, hi = float(p.min()), float(p.max())
            if lo < 0.0 or hi > 1.0:
                raise ValueError(f"{name} must be {allowed}; the array's values span [{lo}, {hi}]")
            return "array", p
        if isinstance(p, np.ndarray):   # 0-d array
            p = p[()]
        if isinstance(p, (bool, np.bool_)) or not isinstance(p, (numbers.Real, np.floating, np.integer)):
            raise ValueError(f"{name} must be {allowed}; got {type(p).__name__}")
        value = float(p)
        if not math.isfinite(value) or not 0.0 <= value <= 1.0:
            raise ValueError(f"{name} must be {allowed}; got {p!r}")
        return "scalar", int(math.floor(value * _ONE + 0.5))

    def _check_shift(self, shift) -> np.ndarray:
        """int32 array (ny, 2), clamped to |sx| <= nx, |sz| <= nz (larger shifts empty the layer)."""
        nx, ny, nz = self.shape
        allowed = f"one (sx, sz) pair of ints or an int array of shape ({ny}, 2)"
        try:
            a = np.asarray(shift)
        except Exception:
            raise ValueError(f"shift must be {allowed}; got {shift!r}") from None
        if a.dtype == np.bool_ or a.dtype.kind not in "iu":
            raise ValueError(f"shift must be {allowed}; got values of dtype {a.dtype}")
        if a.shape == (2,):
            a = np.broadcast_to(a, (ny, 2))
        elif a.shape != (ny, 2):
            raise ValueError(f"shift must be {allowed}; got shape {a.shape}")
        if a.dtype.kind == "u":
            a = np.minimum(a, max(nx, nz))
        a = a.astype(np.int64)
        out = np.empty((ny, 2), dtype=np.int32)
        out[:, 0] = np.clip(a[:, 0], -nx, nx)
        out[:, 1] = np.clip(a[:, 1], -nz, nz)
        return out

    def _upload_probability(self, rule: int, p: np.ndarray) -> None:
        if p is self._prob_cache[rule]:
            return
        data = np.ascontiguousarray(p.transpose(2, 1, 0), dtype="<f4").tobytes()
        self._store_probability(rule, lambda buffer: buffer.write(data))
        self._prob_cache[rule] = p

    def _store_probability(self, rule: int, fill) -> None:
        """``fill(buffer)`` writes per-cell float32 probabilities [x + nx*(y + ny*z)] into ``buffer``;
        they become the rule's per-cell probabilities (threshold planes in the packed layout)."""
        if self._prob_buffers[rule] is None:
            size = 4 * (self._cells if self.layout == "cell" else PLANES * self._count)
            self._prob_buffers[rule] = self.ctx.buffer(reserve=size)
        if self.layout == "cell":
            fill(self._prob_buffers[rule])
            return
        if self._staging is None:
            self._staging = self.ctx.buffer(reserve=4 * self._cells)
        fill(self._staging)
        bind_buffers(self._prog_pack, Prob=self._staging, Planes=self._prob_buffers[rule])
        self._set_grid(self._prog_pack, count=self._words)
        dispatch(self._prog_pack, *self._grid)

    def step_with_texture(self, probabilities, shift=(0, 0)) -> None:
        """One step with per-cell probabilities read on the GPU from a 3D texture of ``shape``
        whose channels are (p_hum, p_act, p_ext, ·) — the weather region volume's
        ``prob_texture`` — so a region-driven step makes no CPU round trip. Same result as
        :meth:`step` with those values as float32 arrays."""
        self._check_alive()
        if not isinstance(probabilities, moderngl.Texture3D) or tuple(probabilities.size) != self.shape \
                or probabilities.components < 3:
            raise ValueError(f"probabilities must be a moderngl.Texture3D of size {self.shape} with channels "
                             f"(p_hum, p_act, p_ext[, ·]); got {probabilities!r}")
        shifts = self._check_shift(shift)
        if self._prog_texture is None:
            self._prog_texture = self.gpu.program(compute_shader="clouds/automaton/from_texture.comp")
        cells = self._prog_texture
        groups = -(-self._cells // _GROUP)
        grid = (min(groups, 65535), -(-groups // 65535), 1)

        def fill_from(channel):
            def fill(buffer):
                bind_textures(cells, u_probabilities=probabilities)
                bind_buffers(cells, Prob=buffer)
                write_uniforms(cells, u_size=self.shape, u_channel=channel)
                dispatch(cells, *grid)
            return fill
        for rule, channel in zip(range(3), (2, 0, 1)):      # RULES order: ext, hum, act
            self._store_probability(rule, fill_from(channel))
            self._prob_cache[rule] = probabilities
        self._run_step(modes=(2, 2, 2), thresholds=(0, 0, 0), shifts=shifts)
