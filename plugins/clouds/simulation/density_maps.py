"""Density maps for empty-space skipping (thesis 7.2.2), computed on the GPU from a smoothed volume.

:class:`DensityMaps` keeps two ``r32f`` texture arrays on the GPU:

* :attr:`DensityMaps.sums` ``(nx, nz, 1 + bands)``: layer 0 is the sum of all height slices seen
  from the top, layer ``1 + b`` the sum over the band of heights
  ``[b * band_height, min((b + 1) * band_height, ny))`` (the last band may be thinner);
* :attr:`DensityMaps.max_maps` ``(gx, gz, 1 + bands)``: each sum map max-downsampled to the
  sprite-group grid, ``gx = ceil(nx / group_x)``, ``gz = ceil(nz / group_z)``; segment ``(i, k)``
  covers ``x in [i * group_x, min((i + 1) * group_x, nx))`` and likewise z, so sizes that do not
  divide the volume give clamped edge segments. A segment is > 0 iff its cells hold any density.

Only the tiny max maps are meant to come back to the CPU, and without a stall:
:meth:`DensityMaps.request_max_maps` queues their copy into a pixel buffer on the GPU and
:meth:`DensityMaps.collect_max_maps` reads that buffer later (frames later in the cloud chain, when
the set is first drawn; it waits only if the copy is not done yet). :meth:`DensityMaps.read_max_maps`
reads them at once (tests and tools). The result equals :func:`atmos.plugins.clouds.simulation.reference.density_maps` up to float32 summation.

Slicing: :meth:`DensityMaps.run` sums the columns ``z in [z0, z1)`` and reduces the segment rows
whose last z row lies in ``[z0, z1)``. Run the slices of a step in increasing z order (as the frame
scheduler does) and every segment row is reduced after all of its columns were summed.
"""
from __future__ import annotations

import math

import moderngl
import numpy as np

from atmos.checks import check_shape, is_int
from atmos.gpu.context import GpuContext, require_gpu
from atmos.plugins.clouds.simulation.smoothing import check_texture_limit, check_volume_texture, check_z_range
from atmos.gpu.uniforms import bind_images, bind_textures, write_uniforms
from atmos.gpu.hazards import dispatch


def group_grid(nx: int, nz: int, group_size) -> tuple[int, int]:
    """Segments per axis: ``ceil(nx / group_x), ceil(nz / group_z)`` (the last ones clamped)."""
    return -(-nx // group_size[0]), -(-nz // group_size[1])


def _check_group_size(group_size) -> tuple[int, int]:
    values = (group_size,) * 2 if is_int(group_size) else group_size
    try:
        values = tuple(values)
    except TypeError:
        values = None
    if values is None or len(values) != 2 or not all(is_int(g) and g >= 1 for g in values):
        raise ValueError(f"group_size must be an int or two ints (group_x, group_z), each >= 1 "
                         f"(cells per sprite-group segment), got {group_size!r}")
    return int(values[0]), int(values[1])


def _read_array(texture, data: bytes | None = None) -> np.ndarray:
    """An r32f texture array (w, h, layers) as float32 ``[layer, w, h]``: read now, or from ``data``
    (its bytes, copied earlier into a pixel buffer)."""
    w, h, layers = texture.size
    if data is None:
        data = texture.read()
    raw = np.frombuffer(data, dtype="<f4").reshape(layers, h, w)
    return np.ascontiguousarray(raw.transpose(0, 2, 1))


class DensityMaps:
    """Top-view density maps of a ``shape = (nx, ny, nz)`` volume; see the module docstring.

    ``band_height``: height slices per band (an int >= 1); ``group_size``: cells per sprite-group
    segment along x and z (an int or two ints >= 1). The programs come from ``gpu.program``.
    """

    def __init__(self, gpu: GpuContext, shape, band_height: int = 4, group_size=(32, 32)):
        ctx = require_gpu(gpu).ctx
        shape = check_shape(shape)
        if not is_int(band_height) or band_height < 1:
            raise ValueError(f"band_height must be an int >= 1 (height slices per band), got {band_height!r}")
        group_size = _check_group_size(group_size)
        nx, ny, nz = shape
        self.gpu, self.ctx = gpu, ctx
        self.shape, self.band_height, self.group_size = shape, int(band_height), group_size
        self.bands = -(-ny // self.band_height)
        self.grid = group_grid(nx, nz, group_size)
        layers = 1 + self.bands
        check_texture_limit(ctx, (nx, nz), "GL_MAX_TEXTURE_SIZE", "the density map size (nx, nz)")
        check_texture_limit(ctx, (layers,), "GL_MAX_ARRAY_TEXTURE_LAYERS", "the number of maps (1 + bands)")
        self._sum_prog = gpu.program(compute_shader="clouds/simulation/density_sums.comp")
        self._max_prog = gpu.program(compute_shader="clouds/simulation/density_max.comp")
        self.sums = self.max_maps = self._pixels = None
        self._requested = False
        try:
            self.sums = ctx.texture_array((nx, nz, layers), 1, dtype="f4")
            self.max_maps = ctx.texture_array((*self.grid, layers), 1, dtype="f4")
            for texture in (self.sums, self.max_maps):
                texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
                texture.write(bytes(4 * math.prod(texture.size)))
            self._pixels = ctx.buffer(reserve=4 * math.prod(self.max_maps.size))   # the max maps' copy
        except Exception:
            self.release()
            raise
        self._released = False

    def run(self, density, z0: int = 0, z1: int | None = None) -> None:
        """Sum columns ``z in [z0, z1)`` (default: all) of the ``density`` Texture3D and reduce the
        segment rows that end there. Checked before anything is dispatched."""
        if self._released:
            raise RuntimeError("these DensityMaps were released")
        check_volume_texture(density, self.shape, "density")
        nx, _, nz = self.shape
        z0, z1 = check_z_range(nz, z0, z1)
        if z0 == z1:
            return
        bind_textures(self._sum_prog, u_density=density)
        bind_images(self._sum_prog, u_sums=self.sums)
        # the programs are shared with other DensityMaps on the GpuContext: this one's uniforms each run
        write_uniforms(self._sum_prog, u_size=self.shape, u_band_height=self.band_height)
        self._sum_prog["u_z0"].value = z0
        dispatch(self._sum_prog, -(-nx // 64), z1 - z0, 1)
        gz0 = z0 // self.group_size[1]
        gz1 = self.grid[1] if z1 == nz else z1 // self.group_size[1]
        if gz1 > gz0:
            bind_textures(self._max_prog, u_sums=self.sums)
            bind_images(self._max_prog, u_max=self.max_maps)
            write_uniforms(self._max_prog, u_extent=(nx, nz), u_group=self.group_size, u_grid=self.grid)
            self._max_prog["u_gz0"].value = gz0
            dispatch(self._max_prog, -(-self.grid[0] // 8), -(-(gz1 - gz0) // 8), 1 + self.bands)

    def read_max_maps(self) -> np.ndarray:
        """The max maps as float32 ``(1 + bands, gx, gz)``: [0] all heights, [1 + b] band b. Waits for
        the GPU; the per-step path is :meth:`request_max_maps` then :meth:`collect_max_maps`."""
        return _read_array(self.max_maps)

    def request_max_maps(self) -> None:
        """Queue a copy of the max maps as they are now into a pixel buffer (GPU side: nothing waits)."""
        if self._released:
            raise RuntimeError("these DensityMaps were released")
        self.max_maps.read_into(self._pixels)
        self._requested = True

    @property
    def requested(self) -> bool:
        """True between :meth:`request_max_maps` and :meth:`collect_max_maps`."""
        return self._requested

    def collect_max_maps(self) -> np.ndarray:
        """The max maps :meth:`request_max_maps` copied, as :meth:`read_max_maps` returns them; reading
        the pixel buffer waits only while the copy is still on its way."""
        if not self._requested:
            raise RuntimeError("collect_max_maps without request_max_maps: nothing was copied")
        self._requested = False
        return _read_array(self.max_maps, self._pixels.read())

    def read_sums(self) -> np.ndarray:
        """The sum maps as float32 ``(1 + bands, nx, nz)`` (a full GPU → CPU copy: tests and tools)."""
        return _read_array(self.sums)

    def release(self) -> None:
        """Free the textures (the programs are the GpuContext's); the maps cannot be used afterwards."""
        self._released = True
        for obj in (self.sums, self.max_maps, self._pixels):
            if obj is not None:
                obj.release()
        self.sums = self.max_maps = self._pixels = None
        self._requested = False

    def __repr__(self) -> str:
        return (f"DensityMaps(shape={self.shape}, band_height={self.band_height}, "
                f"group_size={self.group_size}, grid={self.grid})")

