"""The thesis's shading model (sec. 5.2), kept for comparison in the benchmark.

Each slice multiplies the previous slice's attenuation (bilinear at the shifted position) by a
fixed ratio ``exp(-sigma * rho)`` whatever the angle of the light, starting from 1 on the light-side
slice, and stores it in 8 bits (``levels=255``). An oblique ray crosses ``1/|cos|`` times more
medium per slice than that, so low suns come out too bright. Float64 twin:
``reference.shear_warp_scheme(..., fixed_ratio=True, levels=255)``.
"""
from __future__ import annotations

import numpy as np

from atmos.checks import check_sun_dir
import atmos.plugins.clouds.light.grid as grid
from atmos.gpu.context import GpuContext, require_gpu
from atmos.plugins.clouds.light.shear_warp import ShearWarpShader, read_volume, upload_volume

THESIS_LEVELS = 255


def compute_fixed_ratio(gpu: GpuContext, density, sun_dir, sigma, levels: int = THESIS_LEVELS) -> np.ndarray:
    """Transmittance by the thesis's fixed-ratio model (float32 (nx, ny, nz)); checks like compute_transmittance."""
    require_gpu(gpu)
    density = grid.check_density(density)
    check_sun_dir(sun_dir)
    grid.check_sigma(sigma)
    shader = ShearWarpShader(gpu, density.shape, model="fixed-ratio", levels=levels)
    texture = upload_volume(gpu, density)
    try:
        shader.begin(texture, sun_dir, sigma)
        shader.run_all()
        return read_volume(shader.result)
    finally:
        texture.release()
        shader.release()
