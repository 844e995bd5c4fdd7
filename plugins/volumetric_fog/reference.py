"""numpy float64 reference of the fog medium and its march (``shaders/volumetric_fog/medium.glsl``)."""
from __future__ import annotations

import numpy as np

from atmos.value_noise import fbm
from atmos.plugins.volumetric_fog.settings import VolumetricFogSettings


def density(points: np.ndarray, settings: VolumetricFogSettings, time: float = 0.0) -> np.ndarray:
    """bias − falloff·‖(p − center)/scale‖ + fbm(frequency·(p − center − wind·time)); points (..., 3)."""
    q = np.asarray(points, np.float64) - settings.center
    envelope = settings.bias - settings.falloff * np.linalg.norm(q / settings.scale, axis=-1)
    return envelope + fbm(settings.frequency * (q - np.multiply(settings.wind, time)), settings.octaves, settings.seed)


def march_range(origins, dirs, limits, settings: VolumetricFogSettings):
    """(enter, leave) per ray: the bounding ellipsoid of positive density, clipped to [0, limit]."""
    limits = np.minimum(limits, settings.max_distance)
    n = len(origins)
    if settings.falloff <= 0:
        return np.zeros(n), limits
    radius = (settings.bias + 1.0 - 2.0 ** -settings.octaves) / settings.falloff
    if radius <= 0:
        return np.zeros(n), -np.ones(n)
    o = (origins - settings.center) / settings.scale
    d = dirs / settings.scale
    a, b = (d * d).sum(-1), (o * d).sum(-1)
    c = (o * o).sum(-1) - radius * radius
    disc = b * b - a * c
    r = np.sqrt(np.maximum(disc, 0.0))
    enter = np.maximum((-b - r) / a, 0.0)
    leave = np.minimum((-b + r) / a, limits)
    return np.where(disc > 0, enter, 0.0), np.where(disc > 0, leave, -1.0)


def march(origins, dirs, limits, settings: VolumetricFogSettings, sun_dir, sun_light, ambient_light, time: float = 0.0):
    """(N, 4): in-scattered light rgb and transmittance of N rays, exactly the GLSL march in float64.

    ``dirs`` are normalized here; ``sun_dir`` is the unit vector toward the sun.
    """
    origins = np.asarray(origins, np.float64).reshape(-1, 3)
    dirs = np.asarray(dirs, np.float64).reshape(-1, 3)
    dirs = dirs / np.linalg.norm(dirs, axis=-1, keepdims=True)
    limits = np.broadcast_to(np.asarray(limits, np.float64), (len(origins),))
    sun_dir = np.asarray(sun_dir, np.float64)
    sun_light, ambient_light = np.asarray(sun_light, np.float64), np.asarray(ambient_light, np.float64)
    enter, leave = march_range(origins, dirs, limits, settings)
    dt = (leave - enter) / settings.steps
    light = np.zeros((len(origins), 3))
    trans = np.ones(len(origins))
    active = leave > enter
    sigma = settings.absorption
    for i in range(settings.steps):
        if not active.any():
            break
        idx = np.flatnonzero(active)
        p = origins[idx] + dirs[idx] * (enter[idx] + (i + 0.5) * dt[idx])[:, None]
        d = density(p, settings, time)
        inside = d > 0
        idx, p, d = idx[inside], p[inside], d[inside]
        step_t = np.exp(-sigma * d * dt[idx])
        tl = np.ones(len(idx))
        lit = np.ones(len(idx), bool)       # still marching toward the sun
        for j in range(settings.light_steps):
            dl = density(p + sun_dir * (j * settings.light_step), settings, time)
            hit = lit & (dl > 0)
            tl = np.where(hit, tl * np.exp(-sigma * np.maximum(dl, 0) * settings.light_step), tl)
            lit &= ~(hit & (tl <= 0.01))
        light[idx] += (trans[idx] * (1 - step_t))[:, None] * (ambient_light + sun_light * tl[:, None])
        trans[idx] *= step_t
        active[idx[trans[idx] <= 0.01]] = False
    return np.concatenate([light, trans[:, None]], axis=1)
