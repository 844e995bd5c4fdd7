"""Tileable 3D gradient noise: the GPU volumes (``shaders/fog/noise.comp``) and their float64 reference.

Octave i is periodic gradient noise n_i with an integer lattice of period P_i = ``resolutions[i]``
cells per tile (gradients: one of Perlin's 12 cube-edge vectors, picked by ``lowbias32``-based
:func:`atmos.hashing.hash_counter` of the wrapped cell index, exactly as ``shaders/lib/gradient_noise.glsl``: :mod:`atmos.gradient_noise`).
A world point x maps to tile coordinates u_i = R_y(turn_i) (x - wind_i t) / tile_size and to lattice
coordinates u_i P_i. The texture variant stores n_i at texel centres, (j + 0.5) / texels_per_cell
lattice units, in a (P_i texels_per_cell)^3 r32f volume sampled with repeat + trilinear filtering.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from atmos.gpu.context import GpuContext, require_gpu
from atmos.gradient_noise import periodic_noise, sample_repeat_trilinear
from atmos.hashing import stream_key
from atmos.gpu.uniforms import bind_images, bind_textures
from atmos.gpu.hazards import dispatch

FOG_RULE = 0xF06  # stream id of the fog gradients: stream_key(seed, 0, FOG_RULE, octave)
@lru_cache(maxsize=64)
def octave_key(seed: int, octave: int) -> tuple[int, int]:
    """The (ka, kb) hash keys of one octave's gradients (cached: the fog pass writes them every frame)."""
    ka, kb = stream_key(seed, 0, FOG_RULE, octave)
    return int(ka), int(kb)


def noise_volume_ref(period: int, texels_per_cell: int, key) -> np.ndarray:
    """What noise.comp writes: the (n, n, n) volume indexed [x, y, z], n = period * texels_per_cell."""
    n = period * texels_per_cell
    j = (np.arange(n) + 0.5) / texels_per_cell
    q = np.stack(np.meshgrid(j, j, j, indexing="ij"), axis=-1)
    return periodic_noise(q, period, key)


def tile_coords(world, time: float, wind, turn: float, tile_size: float) -> np.ndarray:
    """u = R_y(turn) (world - wind * time) / tile_size, as in shaders/fog/factor.glsl."""
    p = np.asarray(world, np.float64) - np.asarray(wind, np.float64) * time
    c, s = math.cos(turn), math.sin(turn)
    return np.stack([c * p[..., 0] - s * p[..., 2], p[..., 1], s * p[..., 0] + c * p[..., 2]], -1) / tile_size


def turbulence_ref(world, time: float, settings, volumes: list | None = None) -> np.ndarray:
    """Eq. (5): sum_i noise_i(x) / 2^i, noise_i = clamp(0.5 + 0.5 amplitude n_i, 0, 1), float64.

    ``volumes`` (the octaves' reference or read-back volumes) selects the texture variant;
    None evaluates the noise procedurally.
    """
    total = 0.0
    for i in range(settings.octaves):
        u = tile_coords(world, time, settings.winds[i], settings.turns[i], settings.tile_size)
        period = settings.resolutions[i]
        if volumes is None:
            n = periodic_noise(u * period, period, octave_key(settings.seed, i))
        else:
            n = sample_repeat_trilinear(volumes[i], u)
        total = total + np.clip(0.5 + 0.5 * settings.amplitude * n, 0.0, 1.0) / 2.0**i
    return total


class NoiseVolumes:
    """The octaves' tileable noise textures, made on the GPU by ``fog/noise.comp`` (r32f, repeat, linear).

    ``fill`` prefills every texel first (tests pass NaN to prove each texel is written)."""

    def __init__(self, gpu: GpuContext, settings, fill: float | None = None):
        ctx = require_gpu(gpu).ctx
        shader = gpu.program(compute_shader="fog/noise.comp")
        self.key = (settings.seed, settings.resolutions[:settings.octaves], settings.texels_per_cell)
        self.textures = []
        try:
            for i in range(settings.octaves):
                period, tpc = settings.resolutions[i], settings.texels_per_cell
                n = period * tpc
                tex = ctx.texture3d((n, n, n), 1, dtype="f4")
                self.textures.append(tex)
                if fill is not None:  # tests: a sentinel that any texel the shader misses keeps
                    tex.write(np.full(n ** 3, fill, np.float32).tobytes())
                tex.repeat_x = tex.repeat_y = tex.repeat_z = True
                tex.filter = (ctx.LINEAR, ctx.LINEAR)
                bind_images(shader, volume=tex)
                shader["period"].value = period
                shader["texels_per_cell"].value = tpc
                shader["key"].value = octave_key(settings.seed, i)
                groups = math.ceil(n / 4)
                dispatch(shader, groups, groups, groups)
        except Exception:
            self.release()
            raise

    def matches(self, settings) -> bool:
        return self.key == (settings.seed, settings.resolutions[:settings.octaves], settings.texels_per_cell)

    def bind(self, program) -> None:
        """Bind octave i's volume to the program's ``fog_noise[i]`` (``fog/factor.glsl``)."""
        bind_textures(program, fog_noise=self.textures)

    def read(self) -> list[np.ndarray]:
        """The volumes as float32 arrays indexed [x, y, z] (for tests)."""
        out = []
        for tex in self.textures:
            n = tex.size[0]
            out.append(np.frombuffer(tex.read(), np.float32).reshape(n, n, n).transpose(2, 1, 0).copy())
        return out

    def release(self) -> None:
        for tex in self.textures:
            tex.release()
        self.textures = []
