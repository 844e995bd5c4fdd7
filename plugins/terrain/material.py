"""float64 twin of ``shaders/terrain/material.glsl`` (the terrain's albedo) and the area-weighted mean
albedo of the near heightfield."""
from __future__ import annotations

import numpy as np

from atmos import value_noise
from atmos.collision import height_normal
from atmos.glsl_math import smoothstep
from atmos.plugins.terrain.heightfield import height

OCTAVES = 12
BROAD = 3                             # the first three (2048, 1024, 512 m) make the broad patches
CELL0 = 2048.0                        # m: the broadest octave's lattice cell; each next is 2x finer
GRASS = np.array([[0.09, 0.20, 0.05], [0.25, 0.27, 0.11]])     # lush, dry
ROCK = np.array([[0.20, 0.18, 0.16], [0.42, 0.38, 0.33]])      # dark, light
SNOW = np.array([0.80, 0.82, 0.86])
MEAN_SAMPLES = 512                    # mean_albedo's samples along each side of the square (at most)



def octave(xz, i: int, footprint) -> np.ndarray:
    """Octave ``i`` of the detail at ground points ``xz`` (..., 2), centred on 0 and faded out as
    ``footprint`` (m) grows from 1/4 to 1/2 of its lattice cell (``terrain_octave``)."""
    cell = CELL0 / 2.0 ** i
    fade = 1.0 - smoothstep(0.25, 0.5, np.asarray(footprint, np.float64) / cell)
    noise = value_noise.value_noise(np.asarray(xz, np.float64) / cell + np.array([0.37, 0.71]) * i,
                                    value_noise.key(i))
    return np.where(fade > 0.0, fade * (noise - 0.5), 0.0)


def albedo(p, n, footprint, relief: float, snowline: float, rock_slope: float) -> np.ndarray:
    """Albedo (..., 3) in [0, 1] of the ground at world points ``p`` (..., 3) with unit normals ``n``
    (..., 3), seen with pixel footprints ``footprint`` (m) (``terrain_albedo``): grass, rock where the
    slope's sine passes ``rock_slope``, snow above ``snowline`` × ``relief`` on flatter ground, broken
    by the octaves' detail."""
    p, n = np.asarray(p, np.float64), np.asarray(n, np.float64)
    footprint = np.broadcast_to(np.asarray(footprint, np.float64), p.shape[:-1])
    o = [octave(p[..., [0, 2]], i, footprint) for i in range(OCTAVES)]
    broad = 0.5 * o[0] + 0.3 * o[1] + 0.2 * o[2]
    fine = sum(0.15 * o[i] for i in range(BROAD, OCTAVES))
    slope = np.sqrt(np.maximum(1.0 - n[..., 1] * n[..., 1], 0.0))

    def mix(a, b, t):
        return a + (b - a) * np.asarray(t)[..., None]

    grass = mix(GRASS[0], GRASS[1], np.clip(0.5 + 1.6 * broad + 0.6 * fine, 0.0, 1.0))
    rock = mix(ROCK[0], ROCK[1], np.clip(0.5 + 0.8 * broad + 1.4 * fine, 0.0, 1.0))
    rocky = smoothstep(rock_slope - 0.08, rock_slope + 0.08, slope + 0.15 * broad + 0.12 * fine)
    h = p[..., 1] / max(relief, 1e-3)
    snowy = (smoothstep(snowline - 0.05, snowline + 0.05, h + 0.25 * broad + 0.1 * fine)
             * (1.0 - smoothstep(rock_slope, rock_slope + 0.2, slope + 0.1 * fine)))
    a = mix(mix(grass, rock, rocky), SNOW, snowy)
    return np.clip(a * (1.0 + 0.8 * fine * (1.0 - 0.7 * snowy))[..., None], 0.0, 1.0)


def mean_albedo(size: float, cells: int, relief: float, snowline: float, rock_slope: float) -> np.ndarray:
    """The area-weighted mean albedo (RGB, float64) of the near square: :func:`albedo` at the centres
    of a regular grid of ``min(4 cells, MEAN_SAMPLES)`` samples a side, each weighted by its patch of
    surface (1 / n_y per unit of map area), seen with a footprint of one sample step (the detail
    finer than the samples averages out, as it does on screen)."""
    m = min(4 * cells, MEAN_SAMPLES)
    step = size / m
    axis = -size / 2 + step * (np.arange(m) + 0.5)
    x, z = np.meshgrid(axis, axis, indexing="ij")
    y = height(x, z, relief, size)
    n = height_normal(lambda a, b: height(a, b, relief, size), x, z, eps=0.5 * step)
    a = albedo(np.stack([x, y, z], -1), n, step, relief, snowline, rock_slope)
    w = 1.0 / n[..., 1]
    return (a * w[..., None]).sum((0, 1)) / w.sum()
