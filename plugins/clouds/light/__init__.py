"""Cloud shading: transmittance toward the sun for every voxel of a density volume (thesis ch. 5).

``compute_transmittance`` is the one-shot entry point; ``ShearWarpShader`` / ``ShadingTask`` the
sliced GPU path for the frame scheduler; ``raymarch`` the reference-quality GPU path; ``grid``
the input checks and slice geometry; ``columns`` the light volume's column integrals up and down
(one texture per set for the renderers' sky light and octaves); ``diffusion`` the diffusion field of
the sun's scattered fluence (a CG solve per set, the multiple-scattering term beside the octaves); ``reference`` the float64 numpy references (test oracles);
``scattering`` the cloud light colour (sun x transmittance + ambient, multiple forward scattering
option; the sun and sky colours by time of day are :func:`atmos.lighting.sky_light`).
"""
from __future__ import annotations

import numpy as np

from atmos.checks import check_sun_dir
from atmos.plugins.clouds.light import grid, reference
from atmos.plugins.clouds.light.fixed_ratio import compute_fixed_ratio
from atmos.plugins.clouds.light.raymarch import raymarch
from atmos.plugins.clouds.light.scattering import LightVolumeShader, Scattering, light_volume_reference
from atmos.gpu.context import GpuContext, require_gpu
from atmos.plugins.clouds.light.shear_warp import ShadingTask, ShearWarpShader, groups, program, read_volume, upload_volume
from atmos.gpu.uniforms import bind_images, bind_textures
from atmos.gpu.hazards import dispatch

METHODS = ("shear-warp", "raymarch")


def compute_transmittance(gpu: GpuContext, density, sun_dir, sigma, method: str = "shear-warp",
                          scale: int = 1) -> np.ndarray:
    """float32 (nx, ny, nz): exp(-sigma * integral of density) from each voxel centre toward the sun.

    ``density``: (nx, ny, nz) >= 0, y is height, trilinear between voxel centres, zero outside the
    volume. ``sun_dir``: toward the sun, any length > 0, any direction (from below too).
    ``sigma``: extinction per cell length at density 1, >= 0. ``method``: "shear-warp" (fast) or
    "raymarch" (exact per-voxel march, full resolution only). ``scale``: 1, 2 or 4 (full, half,
    quarter shading resolution; the result is interpolated back to the full grid).
    """
    ctx = require_gpu(gpu).ctx
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}; got {method!r}")
    density = grid.check_density(density)
    check_sun_dir(sun_dir)
    grid.check_sigma(sigma)
    scale = grid.check_scale(scale)
    if method == "raymarch" and scale != 1:
        raise ValueError(f"method='raymarch' runs at full resolution only; allowed is scale=1, got scale={scale}")
    texture = upload_volume(gpu, density)
    made = [texture]
    try:
        if method == "raymarch":
            out = ctx.texture3d(density.shape, 1, dtype="f4")
            made.append(out)
            raymarch(gpu, texture, sun_dir, sigma, out)
            return read_volume(out)
        shader = ShearWarpShader(gpu, density.shape, scale=scale)
        made.append(shader)
        shader.begin(texture, sun_dir, sigma)
        shader.run_all()
        if scale == 1:
            return read_volume(shader.result)
        out = ctx.texture3d(density.shape, 1, dtype="f4")
        made.append(out)
        prog = program(gpu, "upsample")
        bind_textures(prog, coarse=shader.result)
        prog["coarse_size"].value = shader.shading_shape
        bind_images(prog, fine=out)
        dispatch(prog, *(groups(n, 4) for n in density.shape))
        return read_volume(out)
    finally:
        for obj in made:
            obj.release()


__all__ = ["compute_transmittance", "compute_fixed_ratio", "raymarch", "ShearWarpShader", "ShadingTask",
           "Scattering", "LightVolumeShader", "light_volume_reference", "grid", "reference", "METHODS"]
