"""float64 numpy reference of ``shaders/clouds/raymarch/march.glsl`` (run by ``march.comp``) at resolution 1,
midpoint samples (``jitter`` off), no detail noise and no empty-space skipping (which changes only where the steps
fall): the same segments (``step_base + step_growth · s``, s from the near plane or the layer's box
to its far side or the scene), the density trilinear between cell centres (clamp to edge), the
light J of :func:`atmos.plugins.clouds.light.medium.source_reference` with the column depths of
:func:`atmos.plugins.clouds.sprites.reference.column_depth` and the set's diffusion field
(``edge_fade`` 0: neither fades). With ``settings.cloud_type`` (or ``settings.type_map``: the type at each
point, :func:`~atmos.plugins.clouds.volume.shape.type_at`) the density is
:func:`~atmos.plugins.clouds.volume.shape.type_density` of the column's mean density (the light volume's
columns, as ``shape.glsl`` reads them), in the view march and the sun march alike."""
from __future__ import annotations

import numpy as np

from atmos.camera import view_basis
from atmos.plugins.clouds.raymarch.settings import SUN_GROWTH, SUN_SPACING
from atmos.plugins.clouds.volume.shape import TYPE_SUN_STEPS, march_top, type_at, type_density
from atmos.plugins.clouds.volume.light import layer_sun, sun_source_at, unit_direction
from atmos.plugins.clouds.sprites.reference import column_depth
from atmos.plugins.clouds.light.diffusion import diffusion_radiance
from atmos.plugins.clouds.light.medium import source_reference
from atmos.plugins.clouds.light.reference import multilinear


def rays(camera, size) -> tuple[np.ndarray, np.ndarray]:
    """(unit directions (h, w, 3), near-plane distances (h, w)) of the pixel centres, GL row order."""
    w, h = size
    uv = np.stack(np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h), -1)
    ray = np.concatenate([2.0 * uv - 1.0, np.ones((h, w, 1))], -1) @ np.asarray(view_basis(camera, w / h), np.float64).T
    length = np.linalg.norm(ray, axis=-1)
    return ray / length[..., None], float(camera.near) * length


def march_reference(density, transmittance, medium, settings, layout, camera, sun, size, scene=None, field=None,
                    albedo=None, ground_sun: float = 1.0) -> dict:
    """``density`` (nx, ny, nz) and ``transmittance`` (the shading volume, its own shape) of one set;
    ``medium``: the CloudSettings; ``settings``: the RaymarchCloudSettings (steps, step, step_growth,
    min_transmittance, ms_*); ``layout``: the CloudLayout; ``scene``: distance to the scene (h, w), None
    for sky; ``field``: the set's diffusion field (its own shape, 4), None: none; ``albedo``, ``ground_sun``:
    the ground below (:func:`atmos.plugins.clouds.light.medium.environment`). Returns ``light`` (h, w, 3), ``alpha`` (h, w) and ``distance`` (h, w): a·distance."""
    d = np.asarray(density, np.float64)
    trans_volume = np.asarray(transmittance, np.float64)
    lo, hi = np.asarray(layout.lo, np.float64), np.asarray(layout.hi, np.float64)
    extent, cell = hi - lo, np.asarray(layout.cell, np.float64)
    dirs, start = rays(camera, size)
    h, w = start.shape
    dirs, start = dirs.reshape(-1, 3), start.reshape(-1)
    pos = np.asarray(camera.position, np.float64)
    safe = np.where(np.abs(dirs) < 1e-12, 1e-12, dirs)
    top = march_top(tallest_type(settings))                       # towers raise the box's top
    t0, t1 = (lo - pos) / safe, (np.array([hi[0], lo[1] + top * extent[1], hi[2]]) - pos) / safe
    enter = np.maximum(np.minimum(t0, t1).max(-1), start)
    leave = np.maximum(t0, t1).min(-1)
    if scene is not None:
        leave = np.minimum(leave, np.asarray(scene, np.float64).reshape(-1))
    step_base = settings.step * cell.min()
    by_height, sun_color, ambient = layer_sun(sun, layout.heights, top)
    sun_dir = unit_direction(sun)
    column_tau = medium.sigma_t * cell[1]
    lobes = medium.phase.lobes
    density_at = shaped_density(d, settings.cloud_type, trans_volume.shape, extent[1] / cell[1],
                                settings.type_map, lo, extent)

    def sample(i, p):
        uvw = (p - lo) / extent
        typed = (settings.cloud_type is not None or settings.type_map is not None) and settings.sun_steps > 0
        T = sun_transmittance(d, trans_volume, medium.sigma_t, lo, extent, SUN_SPACING * cell.min(),
                              settings.sun_steps + TYPE_SUN_STEPS * typed, sun_dir, p, density_at,
                              shading=not typed, top=top)
        up, down = column_depth(d, uvw, column_tau, trans_volume.shape)
        L = None if field is None else diffusion_radiance(field, uvw, dirs[i], lobes, sun_dir)
        return density_at(uvw), source_reference(
            medium, settings, T, up, down, dirs[i] @ sun_dir, dirs[i][:, 1], sun_color, ambient, sun_dir, L,
            sun_colors=sun_source_at(by_height, uvw[:, 1], top), albedo=albedo, ground_sun=ground_sun)

    return integrate(pos, dirs, enter, leave, settings.steps, step_base, settings.step_growth,
                     settings.min_transmittance, medium.sigma_t, sample, (h, w))


def tallest_type(settings):
    """The tallest type the march shapes with (the map's, the one type, or None: untyped)."""
    if settings.type_map is not None:
        return settings.type_map.highest
    return settings.cloud_type


def shaped_density(density, cloud_type, shading_shape, ny: float, type_map=None, lo=None, extent=None):
    """``shape.glsl``'s shaped_density as a function of uvw (n, 3): the trilinear ``density`` (cloud_type
    and type_map None), else type_density of the columns' (up + down) / ``ny`` (the layer's height in
    cells) of the shading grid ``shading_shape``, of the type at the point (``type_map`` read at world
    lo + uvw extent, else ``cloud_type``)."""
    d = np.asarray(density, np.float64)
    if cloud_type is None and type_map is None:
        return lambda uvw: multilinear(d, uvw * np.array(d.shape, np.float64) - 0.5)

    def at(uvw):
        up, down = column_depth(d, uvw, 1.0, shading_shape)
        t = cloud_type if type_map is None else type_at(None, type_map, lo[0] + uvw[:, 0] * extent[0],
                                                        lo[2] + uvw[:, 2] * extent[2])
        return type_density((up + down) / ny, uvw[:, 1], t)
    return at


def integrate(pos, dirs, enter, leave, steps, step_base, growth, min_transmittance, sigma_t, sample, shape) -> dict:
    """The march both references share: per ray from ``enter`` to ``leave``, steps ``step_base +
    growth · s`` with a midpoint sample, ``sample(rays, points) -> (density, J)``, stopped below
    ``min_transmittance`` or after ``steps``. Returns ``light`` (h, w, 3), ``alpha`` (h, w) and
    ``distance`` (h, w): a·distance."""
    light, trans, weighted = np.zeros((len(enter), 3)), np.ones(len(enter)), np.zeros(len(enter))
    s = enter.copy()
    live = leave > enter
    for _ in range(steps):
        if not live.any():
            break
        i = np.flatnonzero(live)
        dt = np.minimum(step_base + growth * s[i], leave[i] - s[i])
        sp = s[i] + 0.5 * dt
        s[i] += dt
        rho, J = sample(i, pos + dirs[i] * sp[:, None])
        a = 1.0 - np.exp(-sigma_t * rho * dt)
        wgt = trans[i] * a
        light[i] += wgt[:, None] * J
        weighted[i] += wgt * sp
        trans[i] *= 1.0 - a
        live[i] = (s[i] < leave[i]) & (trans[i] >= min_transmittance)
    h, w = shape
    return {"light": light.reshape(h, w, 3), "alpha": (1.0 - trans).reshape(h, w),
            "distance": weighted.reshape(h, w)}


def sun_transmittance(density, transmittance, sigma_t, lo, extent, step, steps, sun_dir, p, density_at=None,
                      shading: bool = True, top: float = 1.0) -> np.ndarray:
    """march.glsl's sun_transmittance at world points ``p`` (n, 3): ``steps`` steps toward ``sun_dir``
    (unit), the first ``step`` m long and each next SUN_GROWTH times the last, the trilinear ``density``
    (or ``density_at(uvw)``: :func:`shaped_density`) at each step's midpoint (0 from the first midpoint
    outside the box on) times the step, then (``shading``; else 1: a cloud type) the
    shading volume ``transmittance`` (trilinear) where they end (1 outside the box); ``steps`` 0: the
    shading volume's T at p."""
    d, tv = np.asarray(density, np.float64), np.asarray(transmittance, np.float64)
    shape, tshape = np.array(d.shape, np.float64), np.array(tv.shape, np.float64)

    def inside(uvw, top=1.0):
        return np.all((uvw >= 0.0) & (uvw <= np.array([1.0, top, 1.0])), axis=-1)

    tau, at, h = np.zeros(len(p)), 0.0, float(step)
    live = np.ones(len(p), bool)
    for _ in range(steps):
        uvw = (p + sun_dir * (at + 0.5 * h) - lo) / extent
        live &= inside(uvw, top)
        rho = multilinear(d, uvw * shape - 0.5) if density_at is None else density_at(uvw)
        tau += np.where(live, h * rho, 0.0)
        at, h = at + h, h * SUN_GROWTH
    end = (p + sun_dir * at - lo) / extent
    far = multilinear(tv, end * tshape - 0.5) if shading else np.ones(len(p))
    if steps > 0:
        far = np.where(live & inside(end), far, 1.0)
    return np.exp(-sigma_t * tau) * far
