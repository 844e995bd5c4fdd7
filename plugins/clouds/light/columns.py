"""The light volume's columns: per cell of the shading grid, the density integrated straight up and
straight down to the volume's faces (``clouds/volume/volume.glsl`` reads them for the occluded sky and
ground light and the octaves' transport depth: one texture fetch instead of marching the columns).

Computed once per texture set (a task of the cloud chain after the density maps, ``slices`` z ranges
of the shading grid, like the smoothing), interpolated mix(A, B, t) by the renderers like the density.
Values are in fine cells of density 1 (``r`` up, ``g`` down), independent of the medium: the renderer
multiplies by ``sigma_t * cell height`` and by the edge fade (a function of x and z only). The fine
density is trilinear between cell centres (clamped in the outer half cells), so along y it is piecewise
linear and the integral is exact; at shading scale s the columns stand at the coarse cell centres.
:func:`column_reference` is the float64 twin of ``shaders/clouds/light/columns.comp``.
"""
from __future__ import annotations

import numpy as np

from atmos.slicing import SliceTask
from atmos.gpu.context import GpuContext, require_gpu
from atmos.graph import TextureDesc
import atmos.plugins.clouds.light.grid as grid
from atmos.plugins.clouds.light.reference import lerp_matrix, multilinear
from atmos.plugins.clouds.light.shear_warp import check_volume_texture, groups, program
from atmos.gpu.uniforms import bind_images, bind_textures
from atmos.gpu.hazards import dispatch

COLUMNS = "columns"          # the texture set's name for it
STORE_MAX = 65000.0          # rg16f's range (columns.comp): an optical depth this large is opaque anyway


def column_desc(shape, scale: int) -> TextureDesc:
    """The texture of a set's columns for a density of ``shape`` at shading ``scale``."""
    return TextureDesc(grid.shading_shape(shape, scale), 2, "f2")


def column_reference(density, scale: int = 1) -> np.ndarray:
    """float64 (cx, cy, cz, 2): (up, down) integrals of ``density`` (fine cells) at the coarse centres."""
    d = grid.check_density(density).astype(np.float64)
    scale = grid.check_scale(scale)
    shape = np.array(d.shape)
    coarse = grid.shading_shape(d.shape, scale)
    h = shape / np.array(coarse)
    mx, mz = (lerp_matrix((np.arange(m) + 0.5) * h[a] - 0.5, shape[a]) for a, m in ((0, coarse[0]), (2, coarse[2])))
    rows = np.einsum("ax,xyz,bz->ayb", mx, d, mz)                       # (cx, ny, cz) at the coarse laterals
    ny = d.shape[1]
    F = np.concatenate([0.5 * rows[:, :1], 0.5 * rows[:, :1] + np.cumsum(0.5 * (rows[:, 1:] + rows[:, :-1]), 1)], 1)
    total = F[:, -1] + 0.5 * rows[:, -1]
    yc = (np.arange(coarse[1]) + 0.5) * h[1] - 0.5
    j = np.clip(np.floor(yc), 0, ny - 1).astype(int)
    j1 = np.minimum(j + 1, ny - 1)
    f, yc = (yc - j)[:, None], yc[:, None]
    r0, r1 = rows[:, j], rows[:, j1]
    down = np.where(yc < 0, r0 * (yc + 0.5), F[:, j] + f * r0 + np.where((j + 1 >= ny)[:, None], 0.0, 0.5 * f * f * (r1 - r0)))
    up = np.maximum(total[:, None] - down, 0.0)
    return np.minimum(np.stack([up, np.maximum(down, 0.0)], -1), STORE_MAX)


def columns_at(columns, uvw) -> np.ndarray:
    """(..., 2): trilinear (clamp to edge) samples of :func:`column_reference`'s volume at texture
    coordinates ``uvw`` (..., 3), what the renderers' texture lookup gives."""
    c = np.asarray(columns, np.float64)
    p = np.asarray(uvw, np.float64) * np.array(c.shape[:3]) - 0.5
    return np.stack([multilinear(c[..., k], p) for k in range(2)], -1)


class ColumnShader:
    """GPU columns: :meth:`run` writes (up, down) of a fine density texture into a :func:`column_desc`
    texture, for coarse z cells ``[z0, z1)`` (all by default)."""

    def __init__(self, gpu: GpuContext, shape, scale: int = 1):
        self.gpu = require_gpu(gpu)
        self.shape = tuple(int(n) for n in shape)
        self.scale = grid.check_scale(scale)
        self.shading_shape = grid.shading_shape(self.shape, self.scale)

    def run(self, density, target, z0: int = 0, z1: int | None = None) -> None:
        check_volume_texture(density, self.shape, "density")
        size = tuple(getattr(target, "size", ()))
        if size != self.shading_shape or getattr(target, "components", 0) != 2 or getattr(target, "dtype", "") != "f2":
            raise ValueError(f"target must be a 2-component f2 3D texture of size {self.shading_shape} "
                             f"(column_desc); got {target!r}")
        nz = self.shading_shape[2]
        z1 = nz if z1 is None else z1
        if not (isinstance(z0, int) and isinstance(z1, int) and 0 <= z0 <= z1 <= nz):
            raise ValueError(f"z range must be ints with 0 <= z0 <= z1 <= {nz}; got z0={z0!r}, z1={z1!r}")
        if z0 == z1:
            return
        prog = program(self.gpu, "columns")
        bind_textures(prog, fine=density)
        prog["fine_size"].value = self.shape
        prog["z0"].value = z0
        bind_images(prog, columns=target)
        dispatch(prog, groups(self.shading_shape[0], 8), groups(z1 - z0, 8))


class ColumnTask(SliceTask):
    """The cloud chain's columns task: ``slices`` z ranges of set C's ``density`` into its
    :data:`COLUMNS` (``shader``: a :class:`ColumnShader`)."""

    def __init__(self, shader: ColumnShader, slices: int = 1, density: str = "density", name: str = "columns"):
        self.shader = shader
        self.density = density
        super().__init__(name, int(slices), self._run)

    def _run(self, index: int, job) -> None:
        n = self.shader.shading_shape[2]
        z0, z1 = n * index // job.slices, n * (index + 1) // job.slices
        self.shader.run(job.target[self.density], job.target[COLUMNS], z0, z1)
