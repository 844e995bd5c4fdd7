"""Cloud field smoothing on the GPU (thesis eq. 2.11 over space only, sec. 4.4).

:class:`Smoother` reads the automaton's cld bits straight from ``CloudAutomaton.state_buffer``
(``"packed"`` or ``"cell"`` layout) and writes a float density volume ``(nx, ny, nz)`` (y is
height) into a 3D texture with one component of dtype ``"f2"`` (r16f, what the renderer uses) or
``"f4"`` (r32f). There is no time term: the renderer interpolates between two completed steps.

Weights and border rule (exactly :func:`atmos.plugins.clouds.simulation.reference.smooth`): separable integer
weights, ``"tent"`` ``w_a(d) = r_a + 1 - |d|`` or ``"box"`` ``w_a(d) = 1``, normalized by their
total so a full neighbourhood gives exactly 1.0; cells outside the volume count as 0, no
renormalization at the borders. A density above 0 is at least :meth:`Smoother.min_density`
(2**-14 for r16f, the smallest normal half float; 0 for r32f), so a cell with any cld in its
neighbourhood is strictly positive in the texture and empty-space skipping never drops it.

Slicing: :meth:`Smoother.run` computes z layers ``[z0, z1)`` per call (the whole volume by
default); :func:`slice_range` splits ``nz`` into even pieces for a frame scheduler.
"""
from __future__ import annotations

import math

import moderngl
import numpy as np

from atmos.checks import check_shape, is_int
from atmos.gpu.context import GpuContext, require_gpu
from atmos.plugins.clouds.automaton import LAYOUTS
from atmos.gpu.uniforms import bind_buffers, bind_images, write_uniforms
from atmos.gpu.hazards import dispatch

WEIGHTS = ("tent", "box")
MAX_RADIUS = 8
F16_MIN_NORMAL = 2.0 ** -14   # smallest normal half float: survives r16f storage and flush-to-zero


def check_radius(radius) -> tuple[int, int, int]:
    """``(rx, ry, rz)`` from an int or three ints in [0, MAX_RADIUS]; ValueError otherwise."""
    allowed = f"an int or three ints (rx, ry, rz), each in [0, {MAX_RADIUS}]"
    values = (radius,) * 3 if is_int(radius) else radius
    try:
        values = tuple(values)
    except TypeError:
        values = None
    if values is None or len(values) != 3 or not all(is_int(r) and 0 <= r <= MAX_RADIUS for r in values):
        raise ValueError(f"radius must be {allowed}, got {radius!r}")
    return tuple(int(r) for r in values)


def check_weights(weights) -> str:
    if weights not in WEIGHTS:
        raise ValueError(f"weights must be one of {WEIGHTS}, got {weights!r}")
    return weights


def axis_weights(kind: str, r: int) -> np.ndarray:
    """Integer weights of offsets ``-r..r`` along one axis (int64, length ``2r + 1``)."""
    d = np.abs(np.arange(-r, r + 1, dtype=np.int64))
    return r + 1 - d if check_weights(kind) == "tent" else np.ones_like(d)


FORMATS = {"f2": "r16f", "f4": "r32f"}       # texture dtype -> image format
MIN_DENSITY = {"f2": F16_MIN_NORMAL, "f4": 0.0}
_LOCAL = (16, 4, 1)
_NUMPY = {"f2": np.float16, "f4": np.float32}


def check_texture_limit(ctx, size, limit_name: str, what: str) -> None:
    """ValueError when a texture ``size`` exceeds the context's ``limit_name`` (e.g. GL_MAX_3D_TEXTURE_SIZE)."""
    limit = int(ctx.info.get(limit_name, 2048))
    if max(size) > limit:
        raise ValueError(f"{what} {tuple(size)} is too big for this GPU: at most {limit} per axis "
                         f"({limit_name}); use a smaller shape")


def slice_range(n: int, index: int, count: int) -> tuple[int, int]:
    """``(start, stop)`` of piece ``index`` of ``count`` near-equal pieces of ``range(n)``."""
    if not (is_int(count) and count >= 1 and is_int(index) and 0 <= index < count):
        raise ValueError(f"slice index must be an int in [0, count) and count an int >= 1, "
                         f"got index={index!r}, count={count!r}")
    return n * index // count, n * (index + 1) // count


def check_z_range(nz: int, z0, z1) -> tuple[int, int]:
    """``(z0, z1)`` with ``z1=None`` meaning nz; ValueError unless ``0 <= z0 <= z1 <= nz``."""
    z1 = nz if z1 is None else z1
    if not (is_int(z0) and is_int(z1) and 0 <= z0 <= z1 <= nz):
        raise ValueError(f"z range must be ints with 0 <= z0 <= z1 <= {nz} (nz), got z0={z0!r}, z1={z1!r}")
    return int(z0), int(z1)


def check_volume_texture(texture, shape, what: str = "texture") -> str:
    """The dtype ("f2"/"f4") of a 1-component float Texture3D of ``shape``; ValueError otherwise."""
    allowed = f"a moderngl Texture3D of size {tuple(shape)}, 1 component, dtype 'f2' or 'f4'"
    if not isinstance(texture, moderngl.Texture3D):
        raise ValueError(f"{what} must be {allowed}; got {type(texture).__name__}")
    if tuple(texture.size) != tuple(shape) or texture.components != 1 or texture.dtype not in FORMATS:
        raise ValueError(f"{what} must be {allowed}; got size {tuple(texture.size)}, "
                         f"{texture.components} components, dtype {texture.dtype!r}")
    return texture.dtype


def read_volume(texture) -> np.ndarray:
    """A 1-component float Texture3D as float32 ``[x, y, z]`` (a GPU → CPU copy: for tests and tools)."""
    nx, ny, nz = texture.size
    dtype = check_volume_texture(texture, (nx, ny, nz))
    raw = np.frombuffer(texture.read(), dtype=_NUMPY[dtype]).reshape(nz, ny, nx)
    return np.ascontiguousarray(raw.transpose(2, 1, 0), dtype=np.float32)


class Smoother:
    """Smooths the cld field of a ``shape = (nx, ny, nz)`` automaton into a density texture.

    ``radius``: an int or ``(rx, ry, rz)``, each in [0, 8]; ``weights``: ``"tent"`` or ``"box"``;
    ``layout``: the automaton's layout, ``"packed"`` or ``"cell"``. See the module docstring.
    The program comes from ``gpu.program`` (shared, released by the GpuContext).
    """

    def __init__(self, gpu: GpuContext, shape, radius=(1, 1, 1), weights: str = "tent", layout: str = "packed"):
        ctx = require_gpu(gpu).ctx
        shape = check_shape(shape)
        radius = check_radius(radius)
        check_weights(weights)
        if layout not in LAYOUTS:
            raise ValueError(f"layout must be one of {LAYOUTS}, got {layout!r}")
        check_texture_limit(ctx, shape, "GL_MAX_3D_TEXTURE_SIZE", "shape")
        nx, ny, nz = shape
        self.gpu, self.ctx = gpu, ctx
        self.shape, self.radius, self.weights, self.layout = shape, radius, weights, layout
        self.words_x = -(-nx // 32)
        words = self.words_x * ny * nz if layout == "packed" else nx * ny * nz
        self.state_bytes = 4 * (3 * words if layout == "packed" else words)
        self._cld_offset = 2 * words if layout == "packed" else 0
        taps = [axis_weights(weights, r) for r in radius]
        rx = radius[0]
        steps = taps[0][rx:] - np.append(taps[0][rx + 1:], 0)     # wx(k) - wx(k + 1), k = 0..rx
        windows = [((1 << (2 * k + 1)) - 1) << (rx - k) for k in range(rx + 1)]
        self._arrays = {"u_cx": steps, "u_window": windows, "u_wy": taps[1], "u_wz": taps[2]}
        self.total = math.prod(int(w.sum()) for w in taps)
        self._released = False

    @classmethod
    def for_automaton(cls, automaton, radius=(1, 1, 1), weights: str = "tent") -> "Smoother":
        """A Smoother matching ``automaton``'s GpuContext, shape and layout."""
        return cls(automaton.gpu, automaton.shape, radius, weights, automaton.layout)

    def min_density(self, dtype: str = "f2") -> float:
        """The smallest density above 0 written to a texture of ``dtype`` ("f2" or "f4")."""
        return MIN_DENSITY[dtype]

    def create_texture(self, dtype: str = "f2") -> moderngl.Texture3D:
        """A zero-filled density texture of this shape (caller releases it); dtype "f2" or "f4"."""
        if dtype not in FORMATS:
            raise ValueError(f"dtype must be one of {tuple(FORMATS)}, got {dtype!r}")
        texture = self.ctx.texture3d(self.shape, 1, dtype=dtype)
        texture.write(bytes(math.prod(self.shape) * np.dtype(_NUMPY[dtype]).itemsize))
        return texture

    def run(self, state_buffer, texture, z0: int = 0, z1: int | None = None) -> None:
        """Smooth layers ``z in [z0, z1)`` (default: all) of ``state_buffer`` into ``texture``.

        Everything is checked before anything is dispatched; a memory barrier follows the dispatch.
        """
        if self._released:
            raise RuntimeError("this Smoother was released")
        if not isinstance(state_buffer, moderngl.Buffer) or state_buffer.size < self.state_bytes:
            got = f"{state_buffer.size} bytes" if isinstance(state_buffer, moderngl.Buffer) else type(state_buffer).__name__
            raise ValueError(f"state_buffer must be a moderngl.Buffer of at least {self.state_bytes} bytes "
                             f"(a {self.layout!r} automaton state of shape {self.shape}); got {got}")
        dtype = check_volume_texture(texture, self.shape)
        z0, z1 = check_z_range(self.shape[2], z0, z1)
        if z0 == z1:
            return
        program = self._program(dtype)
        program["u_z0"].value = z0
        bind_buffers(program, State=state_buffer)
        bind_images(program, u_density=texture)
        nx, ny, _ = self.shape
        dispatch(program, -(-nx // _LOCAL[0]), -(-ny // _LOCAL[1]), z1 - z0)

    def release(self) -> None:
        """The Smoother cannot be used afterwards (it owns no GL objects: its program is the GpuContext's)."""
        self._released = True

    def __repr__(self) -> str:
        return (f"Smoother(shape={self.shape}, radius={self.radius}, weights={self.weights!r}, "
                f"layout={self.layout!r})")

    def _program(self, dtype: str):
        """The shared program for ``dtype`` with this Smoother's uniforms written (other Smoothers on
        the GpuContext use the same program, so they are written before every run)."""
        defines = {"FORMAT": FORMATS[dtype], "LAYOUT_PACKED": int(self.layout == "packed")}
        program = self.gpu.program(compute_shader="clouds/simulation/smooth.comp", defines=defines)
        write_uniforms(program, u_size=self.shape, u_radius=self.radius, u_nwx=self.words_x,
                       u_cld_offset=self._cld_offset, u_total=self.total, u_min_density=MIN_DENSITY[dtype])
        for name, values in self._arrays.items():
            member = program.get(name, None)
            if member is not None:
                data = np.zeros(member.array_length, "<u4")
                data[:len(values)] = values
                member.write(data.tobytes())
        return program
