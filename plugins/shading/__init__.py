"""Cloud shading: transmittance toward the sun for every voxel of a density volume (thesis ch. 5).

``compute_transmittance`` is the one-shot entry point; ``ShearWarpShader`` / ``ShadingStage`` the
sliced GPU path for the frame scheduler; ``raymarch`` the reference-quality GPU path; ``reference``
the float64 numpy references; ``scattering`` the cloud light colour (sun x transmittance + ambient,
multiple forward scattering option, time of day).
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.shading import reference
from atmos.plugins.shading.fixed_ratio import compute_fixed_ratio
from atmos.plugins.shading.raymarch import raymarch
from atmos.plugins.shading.scattering import (LightVolumeShader, Scattering, light_volume_reference,
                                              sky_light)
from atmos.plugins.shading.shear_warp import (ShadingStage, ShearWarpShader, context_of, program,
                                              read_volume, upload_volume, groups)

METHODS = ("shear-warp", "raymarch")


def compute_transmittance(ctx, density, sun_dir, sigma, method: str = "shear-warp", scale: int = 1) -> np.ndarray:
    """float32 (nx, ny, nz): exp(-sigma * integral of density) from each voxel centre toward the sun.

    ``density``: (nx, ny, nz) >= 0, y is height, trilinear between voxel centres, zero outside the
    volume. ``sun_dir``: toward the sun, any length > 0, any direction (from below too).
    ``sigma``: extinction per cell length at density 1, >= 0. ``method``: "shear-warp" (fast) or
    "raymarch" (exact per-voxel march, full resolution only). ``scale``: 1, 2 or 4 (full, half,
    quarter shading resolution; the result is interpolated back to the full grid).
    """
    ctx = context_of(ctx)
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}; got {method!r}")
    density = reference.check_density(density)
    reference.check_sun_dir(sun_dir)
    reference.check_sigma(sigma)
    scale = reference.check_scale(scale)
    if method == "raymarch" and scale != 1:
        raise ValueError(f"method='raymarch' runs at full resolution only; allowed is scale=1, got scale={scale}")
    texture = upload_volume(ctx, density)
    made = [texture]
    try:
        if method == "raymarch":
            out = ctx.texture3d(density.shape, 1, dtype="f4")
            made.append(out)
            raymarch(ctx, texture, sun_dir, sigma, out)
            return read_volume(out)
        shader = ShearWarpShader(ctx, density.shape, scale=scale)
        made.append(shader)
        shader.begin(texture, sun_dir, sigma)
        shader.run_all()
        if scale == 1:
            return read_volume(shader.result)
        out = ctx.texture3d(density.shape, 1, dtype="f4")
        made.append(out)
        prog = program(ctx, "upsample")
        shader.result.use(0)
        prog["coarse"].value = 0
        prog["coarse_size"].value = shader.shading_shape
        out.bind_to_image(0, read=False, write=True)
        prog.run(*(groups(n, 4) for n in density.shape))
        ctx.memory_barrier()
        return read_volume(out)
    finally:
        for obj in made:
            obj.release()


__all__ = ["compute_transmittance", "compute_fixed_ratio", "raymarch", "ShearWarpShader", "ShadingStage",
           "Scattering", "LightVolumeShader", "light_volume_reference", "sky_light", "reference", "METHODS"]
