"""Reference-quality GPU transmittance: one invocation per voxel marches toward the sun.

The march is exact for trilinear density (to float32): it steps from plane crossing to plane
crossing (integer planes, where the trilinear pieces change, and the half-integer box faces; all
at ``m / (2|u_a|)`` from a voxel centre) and integrates each cubic piece with two-point
Gauss-Legendre. Cost grows with the path length; the shear-warp is the fast path.
"""
from __future__ import annotations

from atmos.checks import check_sun_dir
import atmos.plugins.clouds.light.grid as grid
from atmos.gpu.context import GpuContext, require_gpu
from atmos.plugins.clouds.light.shear_warp import _RESULT_FORMATS, check_volume_texture, groups, program
from atmos.gpu.uniforms import bind_images, bind_textures
from atmos.gpu.hazards import dispatch


def raymarch(gpu: GpuContext, density_texture, sun_dir, sigma, target) -> None:
    """Write ``exp(-sigma * optical depth)`` of every voxel of ``density_texture`` into ``target``
    (a 1-component ``f2``/``f4`` 3D texture of the same size)."""
    require_gpu(gpu)
    shape = tuple(density_texture.size)
    check_volume_texture(density_texture, shape, "density_texture")
    check_volume_texture(target, shape, "target", dtypes=tuple(_RESULT_FORMATS))
    u = check_sun_dir(sun_dir)
    sigma = min(grid.check_sigma(sigma), grid.SIGMA_MAX)
    prog = program(gpu, "raymarch", RESULT_FORMAT=_RESULT_FORMATS[target.dtype])
    bind_textures(prog, density=density_texture)
    prog["sun_dir"].value = tuple(float(x) for x in u)
    prog["sigma"].value = sigma
    bind_images(prog, result=target)
    dispatch(prog, *(groups(n, 4) for n in shape))
