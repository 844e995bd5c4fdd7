"""Transmittance toward the sun by shear-warp (thesis sec. 5.2) on the GPU: sun-aligned columns, one
dispatch per run of slices.

The slices run along the axis closest to the light (y, x or z, either direction; ties go to y, then
x, then z), starting on the light side. Each column of ``shear_warp.comp`` follows one straight ray
away from the sun through the slices, adding ``sigma * mean density * true path length`` per step
(trapezoid, partial where the ray crosses the box) in float, so no interpolation error builds up
along a ray; the cells of each slice take their depth bicubically from the columns around them (the
warp) and store ``exp(-depth)`` in the result volume. A group of 16×16 columns shares each slice's
depths in shared memory (one ``barrier()`` per slice), and two ping-pong ``r32f`` images carry the
columns' depths from one run of slices to the next: no CPU round trip, no memory barrier between
slices. The float64 twin is :func:`reference.shear_warp_scheme`. The thesis's own model
(``model="fixed-ratio"``: a fixed attenuation ratio per slice in 8 bits) runs a dispatch per slice
(``fixed_ratio.comp``), for comparison.

Sliced use (thesis sec. 7.1): :meth:`ShearWarpShader.begin` latches the density, sun direction and
sigma (a sun moving later changes the *next* pass, never this one), then :meth:`run_slices` runs
any ``[i0, i1)`` of the :attr:`slice_count` slices in order; :class:`ShadingTask` wraps that as a
:class:`~atmos.slicing.SliceTask` writing into texture set C.
"""
from __future__ import annotations

import math
import struct

import moderngl
import numpy as np

from atmos.checks import check_shape, check_sun_dir
from atmos.slicing import SliceTask
from atmos.gpu.context import GpuContext, require_gpu
from atmos.gpu.uniforms import bind_buffers, bind_images, bind_textures, write_block, write_uniforms
import atmos.plugins.clouds.light.grid as grid
from atmos.gpu.hazards import dispatch, dispatch_indirect
from atmos.gpu.block_table import BlockTable, ints

_RESULT_FORMATS = {"f4": "r32f", "f2": "r16f"}
_UNIT = ((1, 0, 0), (0, 1, 0), (0, 0, 1))      # axis_a/b/c by axis
SLICE_BINDING = 1                               # fixed_ratio.comp's Slice block
COLUMNS_BLOCK, COLUMNS_BINDING = "Columns", 1   # shear_warp.comp's block of one run's constants
_COLUMNS = struct.Struct("<4i4i4i4f")            # std140: grid, axes, columns, light (see the shader)
OWN = 13                                        # columns a 16x16 group writes per side (shear_warp.comp's OWN)
_BAND_EMPTY = struct.pack("<4I", 0, 1, 1, 0)     # shear_warp.comp's band_args before a run: no groups, no cells


def program(gpu: GpuContext, name: str, **defines):
    """``shaders/clouds/light/<name>.comp`` with ``defines``, from the GpuContext's program cache."""
    return gpu.program(compute_shader=f"clouds/light/{name}.comp", defines=defines)


def upload_volume(gpu: GpuContext, volume: np.ndarray):
    """A 1-component float32 3D texture of size (nx, ny, nz) holding ``volume[x, y, z]`` (caller releases it)."""
    data = np.ascontiguousarray(np.asarray(volume, dtype=np.float32).transpose(2, 1, 0))
    texture = require_gpu(gpu).ctx.texture3d(volume.shape, 1, data.tobytes(), dtype="f4")
    texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
    return texture


def read_volume(texture) -> np.ndarray:
    """A 1-component float 3D texture as a float32 (nx, ny, nz) array."""
    nx, ny, nz = texture.size
    raw = np.frombuffer(texture.read(), dtype=np.float16 if texture.dtype == "f2" else np.float32)
    return raw.reshape(nz, ny, nx).transpose(2, 1, 0).astype(np.float32)


def groups(n: int, size: int) -> int:
    return max(1, -(-int(n) // size))


def check_volume_texture(texture, shape, what: str, dtypes=("f1", "f2", "f4")) -> None:
    size = tuple(getattr(texture, "size", ()))
    if not isinstance(texture, moderngl.Texture3D) or size != tuple(shape) or texture.dtype not in dtypes:
        raise ValueError(f"{what} must be a moderngl 3D texture of size {tuple(shape)} and dtype in {dtypes}; "
                         f"got {type(texture).__name__} size {size or '?'} dtype {getattr(texture, 'dtype', '?')!r}")


class ShearWarpShader:
    """Shear-warp shading of a density volume of ``shape`` (nx, ny, nz) at 1/``scale`` resolution.

    ``result`` is the transmittance volume (float32, :attr:`shading_shape`), unless :meth:`begin`
    was given a ``target`` texture. ``model="fixed-ratio"`` runs the thesis's model instead
    (``levels=255``: 8-bit rounding per slice), for comparison.
    """

    def __init__(self, gpu: GpuContext, shape, scale: int = 1, model: str = "true-path", levels: int = 0):
        self.gpu = require_gpu(gpu)
        self.ctx = gpu.ctx
        self.shape = check_shape(shape)
        self.scale = grid.check_scale(scale)
        if model not in ("true-path", "fixed-ratio"):
            raise ValueError(f"model must be 'true-path' or 'fixed-ratio'; got {model!r}")
        if isinstance(levels, bool) or not isinstance(levels, int) or not 0 <= levels <= 65535:
            raise ValueError(f"levels must be an int in [0, 65535] (0: no rounding); got {levels!r}")
        self.model, self.levels = model, levels
        self.shading_shape = grid.shading_shape(self.shape, self.scale)
        side = max(self.shading_shape)
        self._objects = []
        self.result = self._track(self.ctx.texture3d(self.shading_shape, 1, dtype="f4"))
        self._coarse = (self._track(self.ctx.texture3d(self.shading_shape, 1, dtype="f4"))
                        if self.scale > 1 else None)
        if model == "fixed-ratio":       # the previous slice's T, ping-pong; one Slice record per dispatch
            self._slices = [self._track(self.ctx.texture((side, side), 1, dtype="f4")) for _ in range(2)]
            self._slice_table = self._track(BlockTable(gpu, SLICE_BINDING,
                                                       [ints(j, first) for j in range(side) for first in (0, 1)]))
        else:       # each column's depth and last rho between runs, ping-pong: at most slices + side + 6 columns
            carry = -(-(2 * side + 6) // OWN) * OWN
            self._carry = [self._track(self.ctx.texture((carry, carry), 2, dtype="f4")) for _ in range(2)]
            self._band = None        # the cells that march their own ray (_band_for: grown to the longest run)
        self._plan = None
        self._columns = None
        self._flip = False
        self._next = 0

    def _track(self, obj):
        self._objects.append(obj)
        return obj

    # -- a pass -----------------------------------------------------------------------------------
    def begin(self, density_texture, sun_dir, sigma, target=None) -> int:
        """Latch the inputs of one shading pass; returns :attr:`slice_count`.

        ``density_texture``: a 1-component 3D texture of :attr:`shape` (not changed until the pass
        ends); ``target``: None (use :attr:`result`) or an ``f2``/``f4`` 1-component 3D texture of
        :attr:`shading_shape`. Checks everything before touching any state.
        """
        check_volume_texture(density_texture, self.shape, "density_texture")
        if target is not None:
            check_volume_texture(target, self.shading_shape, "target", dtypes=tuple(_RESULT_FORMATS))
        u = check_sun_dir(sun_dir)
        sigma = min(grid.check_sigma(sigma), grid.SIGMA_MAX)
        if self._coarse is not None:
            prog = program(self.gpu, "downsample", SCALE=self.scale)
            bind_textures(prog, fine=density_texture)
            write_uniforms(prog, fine_size=self.shape)
            bind_images(prog, coarse=self._coarse)
            dispatch(prog, *(groups(n, 4) for n in self.shading_shape))
            density_texture = self._coarse
        spacing = np.array(self.shape) / np.array(self.shading_shape)
        self._plan = grid.SlicePlan(self.shading_shape, u, spacing)
        self._columns = self._plan.column_range() if self.model == "true-path" else None
        self._density, self._sigma = density_texture, sigma
        self._target = self.result if target is None else target
        self._next = 0
        return self.slice_count

    @property
    def slice_count(self) -> int:
        """Slices of the current pass (the shading grid's extent along the slicing axis); 0 before begin."""
        return self._plan.count if self._plan else 0

    @property
    def next_slice(self) -> int:
        return self._next

    @property
    def done(self) -> bool:
        return self._plan is not None and self._next >= self._plan.count

    @property
    def axis(self) -> int:
        """Slicing axis of the current pass (0 x, 1 y, 2 z)."""
        return self._plan.axis

    def run_slices(self, i0: int, i1: int) -> None:
        """Run slices ``i0 .. i1-1`` of the current pass; ``i0`` must be :attr:`next_slice`."""
        if self._plan is None:
            raise ValueError("run_slices before begin(): call begin(density_texture, sun_dir, sigma) first")
        count = self._plan.count
        if not (isinstance(i0, int) and isinstance(i1, int)) or i0 != self._next or not i0 <= i1 <= count:
            raise ValueError(f"run_slices({i0!r}, {i1!r}): slices run in order; allowed is i0 == {self._next} "
                             f"(the next slice) and i0 <= i1 <= {count}")
        if i0 == i1:
            return
        if self.model == "fixed-ratio":
            self._run_fixed_ratio(i0, i1)
        else:
            self._run_columns(i0, i1)
        self._next = i1

    def _run_columns(self, i0: int, i1: int) -> None:
        """Slices ``i0 .. i1-1``: one dispatch over the columns (``shear_warp.comp``), which lists the cells
        its warp cannot interpolate, and one indirect dispatch over those (``shear_warp_rays.comp``:
        their own rays); each writes its own cells of the result."""
        plan = self._plan
        first, count = self._columns
        fmt = _RESULT_FORMATS[self._target.dtype]
        (b, c), v = plan.lateral, plan.lateral_step
        block = _COLUMNS.pack(*self.shading_shape, plan.count, plan.axis, b, c, plan.sign, int(first[0]),
                              int(first[1]), i0, i1, float(v[0]), float(v[1]), plan.length, self._sigma)
        carry_in, carry_out = self._carry if self._flip else self._carry[::-1]
        self._flip = not self._flip
        band = self._band_for(self.shading_shape[b] * self.shading_shape[c] * (i1 - i0))
        columns = program(self.gpu, "shear_warp", RESULT_FORMAT=fmt)
        write_block(columns, COLUMNS_BLOCK, COLUMNS_BINDING, block)
        bind_textures(columns, density=self._density)
        bind_images(columns, carry_in=carry_in, carry_out=carry_out, result=self._target)
        bind_buffers(columns, Band=band)
        dispatch(columns, groups(count[0], OWN), groups(count[1], OWN))
        rays = program(self.gpu, "shear_warp_rays", RESULT_FORMAT=fmt)
        write_block(rays, COLUMNS_BLOCK, COLUMNS_BINDING, block)
        bind_textures(rays, density=self._density)
        bind_images(rays, result=self._target)
        bind_buffers(rays, Band=band)
        dispatch_indirect(rays, band)

    def _band_for(self, cells: int):
        """The list of cells that march their own ray, room for ``cells`` (every cell of the run's slices),
        emptied: the rays' dispatch arguments (groups, 1, 1) and the count, then (x | y << 16, k) per cell."""
        size = 16 + 8 * cells
        if self._band is None or self._band.size < size:
            if self._band is not None:
                self._objects.remove(self._band)
                self._band.release()
            self._band = self._track(self.ctx.buffer(reserve=size))
        self._band.write(_BAND_EMPTY)
        return self._band

    def _run_fixed_ratio(self, i0: int, i1: int) -> None:
        """Slices ``i0 .. i1-1`` of the thesis's model: a dispatch per slice (``fixed_ratio.comp``)."""
        plan = self._plan
        prog = program(self.gpu, "fixed_ratio", RESULT_FORMAT=_RESULT_FORMATS[self._target.dtype],
                       LEVELS=self.levels)
        a, (b, c) = plan.axis, plan.lateral
        write_uniforms(prog, size=self.shading_shape, axis_a=_UNIT[a], axis_b=_UNIT[b], axis_c=_UNIT[c],
                       step_dir=tuple(map(float, plan.step)), sigma=self._sigma)
        bind_textures(prog, density=self._density)
        bind_images(prog, result=self._target)
        gb, gc = groups(self.shading_shape[b], 8), groups(self.shading_shape[c], 8)
        order = plan.order
        for i in range(i0, i1):
            src, dst = self._slices[i % 2], self._slices[1 - i % 2]
            bind_images(prog, prev_slice=src, next_slice=dst)
            self._slice_table.use(2 * int(order[i]) + (i == 0))     # the Slice block: (slice, first)
            dispatch(prog, gb, gc)

    def run_all(self) -> None:
        """Run the remaining slices of the current pass."""
        self.run_slices(self._next, self.slice_count)

    def release(self) -> None:
        for obj in self._objects:
            obj.release()
        self._objects.clear()



class ShadingTask(SliceTask):
    """The shading task of a :class:`~atmos.slicing.SlicedJob`: ``slices_per_run`` shear-warp slices
    per job slice, reading ``set[density]`` and writing ``set[result]`` of texture set C.

    ``sun`` and ``sigma`` are values or zero-argument callables, read once when a step starts (the
    slice count depends on the slicing axis), so the whole pass uses one sun direction.
    """

    def __init__(self, shader: ShearWarpShader, sun, sigma, density: str = "density",
                 result: str = "transmittance", slices_per_run: int = 1, name: str = "shading"):
        if isinstance(slices_per_run, bool) or not isinstance(slices_per_run, int) or slices_per_run < 1:
            raise ValueError(f"slices_per_run must be an int >= 1; got {slices_per_run!r}")
        self.shader, self.sun, self.sigma = shader, sun, sigma
        self.density, self.result, self.slices_per_run = density, result, slices_per_run
        self._latched = None
        super().__init__(name, self._count, self._run)

    def _count(self) -> int:
        sun = self.sun() if callable(self.sun) else self.sun
        sigma = self.sigma() if callable(self.sigma) else self.sigma
        u, sigma = check_sun_dir(sun), grid.check_sigma(sigma)
        spacing = np.array(self.shader.shape) / np.array(self.shader.shading_shape)
        slices = grid.SlicePlan(self.shader.shading_shape, u, spacing).count
        self._latched = (u, sigma)
        return math.ceil(slices / self.slices_per_run)

    def _run(self, index: int, job) -> None:
        shader = self.shader
        if index == 0:
            shader.begin(job.target[self.density], *self._latched, target=job.target[self.result])
        start = index * self.slices_per_run
        shader.run_slices(start, min(start + self.slices_per_run, shader.slice_count))
