"""Cloud light for the renderer: sun colour x transmittance + ambient sky colour, by time of day.

Single scattering with an ambient term (thesis sec. 5.1) or Harris's multiple forward scattering
(thesis sec. 2.4.1). Harris's recurrence along the light path, per step of transmittance ``t``,
``I_next = I * (t + albedo * forward * (1 - t))`` (the light removed from the beam that is scattered
into the forward cone stays in it), tends for small steps to Beer-Lambert with the reduced extinction
``sigma * (1 - albedo * forward)``: so multiple forward scattering is the same shear-warp pass with
:meth:`Scattering.extinction` (no extra GPU work, and independent of the slice spacing, unlike the
per-particle recurrence). :func:`harris_reference` is the discrete recurrence, for checking that.

For the renderer: per voxel ``light.rgb = sun_color * T + ambient`` and ``light.a = T``, from
:class:`LightVolumeShader` (GPU) or :func:`light_volume_reference` (numpy); colours from
:func:`atmos.lighting.sky_light` (``sun_dir`` of the :class:`~atmos.lighting.Sun` resource, ambient
scaled by :attr:`Scattering.ambient`). Below the horizon the sun colour is 0: ambient only (night).
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

import atmos.plugins.clouds.light.grid as grid
from atmos.gpu.context import GpuContext, require_gpu
from atmos.plugins.clouds.light.shear_warp import _RESULT_FORMATS, check_volume_texture, groups, program
from atmos.gpu.uniforms import bind_images, bind_textures
from atmos.gpu.hazards import dispatch

MODES = ("single", "multiple-forward")


def _fraction(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not 0 <= float(value) <= 1:
        raise ValueError(f"Scattering.{name} must be a real number in [0, 1]; got {value!r}")
    return float(value)


@dataclass(frozen=True)
class Scattering:
    """How cloud voxels are lit: ``mode`` "single" (direct sun + ambient) or "multiple-forward" (Harris).

    ``albedo``: scattered / extinguished light; ``forward``: the part of the scattered light that stays
    in the forward cone (Harris's phase-function lobe); ``ambient``: scale of the sky's ambient colour.
    """
    mode: str = "single"
    albedo: float = 0.9
    forward: float = 0.5
    ambient: float = 1.0

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError(f"Scattering.mode must be one of {MODES}; got {self.mode!r}")
        _fraction("albedo", self.albedo)
        _fraction("forward", self.forward)
        if isinstance(self.ambient, bool) or not isinstance(self.ambient, numbers.Real) \
                or not math.isfinite(self.ambient) or self.ambient < 0:
            raise ValueError(f"Scattering.ambient must be a finite real number >= 0; got {self.ambient!r}")

    def extinction(self, sigma) -> float:
        """The sigma to shade with: ``sigma`` (single) or ``sigma * (1 - albedo * forward)`` (multiple forward)."""
        sigma = grid.check_sigma(sigma)
        return sigma if self.mode == "single" else sigma * (1.0 - self.albedo * self.forward)


def harris_reference(rho, sigma: float, step: float, albedo: float, forward: float) -> np.ndarray:
    """Harris's discrete multiple forward scattering along one light path (float64).

    ``rho``: densities at the steps, light side first; returns the light reaching each step's end.
    """
    t = np.exp(-sigma * np.asarray(rho, dtype=np.float64) * step)
    return np.cumprod(t + albedo * forward * (1.0 - t))


def light_volume_reference(transmittance, sun_color, ambient) -> np.ndarray:
    """(nx, ny, nz, 4) float64: rgb = sun_color * T + ambient, a = T."""
    t = np.asarray(transmittance, dtype=np.float64)[..., None]
    rgb = t * np.asarray(sun_color, dtype=np.float64) + np.asarray(ambient, dtype=np.float64)
    return np.concatenate([rgb, t], axis=-1)


class LightVolumeShader:
    """GPU light volume: ``run(transmittance, target, sun_color, ambient)`` writes rgba (see module doc)."""

    def __init__(self, gpu: GpuContext):
        self.gpu = require_gpu(gpu)
        self.ctx = gpu.ctx

    def run(self, transmittance, target, sun_color, ambient) -> None:
        """``target``: a 4-component ``f2``/``f4`` 3D texture of the transmittance texture's size."""
        shape = tuple(transmittance.size)
        check_volume_texture(transmittance, shape, "transmittance")
        if tuple(getattr(target, "size", ())) != shape or getattr(target, "components", 0) != 4 \
                or getattr(target, "dtype", None) not in _RESULT_FORMATS:
            raise ValueError(f"target must be a 4-component f2/f4 3D texture of size {shape}; got {target!r}")
        colors = []
        for name, c in (("sun_color", sun_color), ("ambient", ambient)):
            c = np.asarray(c, dtype=np.float64)
            if c.shape != (3,) or not np.isfinite(c).all() or (c < 0).any():
                raise ValueError(f"{name} must be 3 finite numbers >= 0 (RGB); got {c!r}")
            colors.append(tuple(float(x) for x in c))
        fmt = {"f2": "rgba16f", "f4": "rgba32f"}[target.dtype]
        prog = program(self.gpu, "light", RESULT_FORMAT=fmt)
        bind_textures(prog, transmittance=transmittance)
        prog["sun_color"].value, prog["ambient"].value = colors
        bind_images(prog, light=target)
        dispatch(prog, *(groups(n, 4) for n in shape))
