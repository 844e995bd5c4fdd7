"""numpy float64 reference of the fog medium and its march (``shaders/volumetric_fog/medium.glsl``)."""
from __future__ import annotations

import numpy as np

from atmos.froxels import column_rays, froxel_distance
from atmos.value_noise import fbm
from atmos.plugins.volumetric_fog.noise import LATTICE
from atmos.plugins.volumetric_fog.settings import VolumetricFogSettings


def density(points: np.ndarray, settings: VolumetricFogSettings, time: float = 0.0) -> np.ndarray:
    """bias − falloff·‖(p − center)/scale‖ + fbm(frequency·(p − center − wind·time)) on the lattice
    repeating every LATTICE cells (the baked noise's, exact); points (..., 3)."""
    q = np.asarray(points, np.float64) - settings.center
    envelope = settings.bias - settings.falloff * np.linalg.norm(q / settings.scale, axis=-1)
    return envelope + fbm(settings.frequency * (q - np.multiply(settings.wind, time)), settings.octaves, settings.seed, LATTICE)


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


def march(origins, dirs, limits, settings: VolumetricFogSettings, sun_dir, sun_light, ambient_light, time: float = 0.0,
          cloud_tau=None):
    """(N, 4): in-scattered light rgb and transmittance of N rays, exactly the GLSL march in float64.

    ``dirs`` are normalized here; ``sun_dir`` is the unit vector toward the sun; ``cloud_tau``: None, or
    the clouds' optical depth toward the sun at points (n, 3) (the cloud shadow map's, FOG_CLOUD_SHADOWS).
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
        tl = sun_transmittance(p, settings, sun_dir, time, cloud_tau)
        light[idx] += (trans[idx] * (1 - step_t))[:, None] * (ambient_light + sun_light * tl[:, None])
        trans[idx] *= step_t
        active[idx[trans[idx] <= 0.01]] = False
    return np.concatenate([light, trans[:, None]], axis=1)


def froxel_volume(camera_pos, basis, froxels, settings: VolumetricFogSettings, sun_dir, sun_light, ambient_light,
                  knee: float, time: float = 0.0, jitter: float = 0.5, cloud_tau=None) -> np.ndarray:
    """(W, H, D + 1, 4) float64: volumetric_fog/froxels.comp — each column's ray through uv = ((x, y) + 0.5)
    / (W, H) (``basis``: atmos.camera.view_basis) marched one sample per slice, at the share ``jitter`` of
    the slice's part inside the envelope; layer k holds (light,
    transmittance) from the camera to slice boundary k."""
    w, h, d = froxels
    _, dirs = column_rays(basis, w, h)
    origins = np.broadcast_to(np.asarray(camera_pos, np.float64), dirs.shape)
    enter, leave = march_range(origins, dirs, np.full(len(dirs), settings.max_distance), settings)
    bounds = froxel_distance(np.arange(d + 1) / d, settings.max_distance, knee)
    sun_dir = np.asarray(sun_dir, np.float64)
    sun_light, ambient_light = np.asarray(sun_light, np.float64), np.asarray(ambient_light, np.float64)
    out = np.zeros((len(dirs), d + 1, 4))
    light, trans = np.zeros((len(dirs), 3)), np.ones(len(dirs))
    out[:, 0, 3] = 1.0
    sigma = settings.absorption
    for k in range(1, d + 1):
        a, b = np.maximum(bounds[k - 1], enter), np.minimum(bounds[k], leave)
        idx = np.flatnonzero((b > a) & (trans > 0.01))
        p = origins[idx] + dirs[idx] * (a[idx] + jitter * (b[idx] - a[idx]))[:, None]
        dens = density(p, settings, time)
        inside = dens > 0
        idx, p, dens = idx[inside], p[inside], dens[inside]
        step_t = np.exp(-sigma * dens * (b[idx] - a[idx]))
        tl = sun_transmittance(p, settings, sun_dir, time, cloud_tau)
        light[idx] += (trans[idx] * (1 - step_t))[:, None] * (ambient_light + sun_light * tl[:, None])
        trans[idx] *= step_t
        out[:, k, :3], out[:, k, 3] = light, trans
    return out.reshape(w, h, d + 1, 4)


def sun_transmittance(p, settings: VolumetricFogSettings, sun_dir, time: float = 0.0, cloud_tau=None) -> np.ndarray:
    """medium.glsl fog_sun_transmittance at points p (n, 3): light_steps samples toward the sun, stopping at
    0.01; times exp(−cloud_tau(p)) when given (the clouds' shadow)."""
    tl = np.ones(len(p))
    lit = np.ones(len(p), bool)
    for j in range(settings.light_steps):
        dl = density(p + sun_dir * (j * settings.light_step), settings, time)
        hit = lit & (dl > 0)
        tl = np.where(hit, tl * np.exp(-settings.absorption * np.maximum(dl, 0) * settings.light_step), tl)
        lit &= ~(hit & (tl <= 0.01))
    return tl if cloud_tau is None else tl * np.exp(-cloud_tau(p))
