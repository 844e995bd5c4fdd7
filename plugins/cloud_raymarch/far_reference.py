"""float64 numpy reference of the march's volumetric far field (``shaders/cloud_raymarch/far.glsl`` in
``march.frag`` with FAR_FIELD): the profile, its light, and the march of rays that stay outside the
volume's footprint (far weight 1; mip 0 of the far field's textures, detail noise off, midpoints)."""
from __future__ import annotations

import numpy as np

from atmos.plugins.cloud_far_field.reference import column_at_rank, field_fbm, field_rank
from atmos.plugins.cloud_raymarch.far import FAR_BASE, FAR_BASE_SOFT, FAR_BODY, FAR_MAX, FAR_TOP_SOFT, SUN_STEPS, sun_steps
from atmos.plugins.cloud_raymarch.reference import integrate, rays
from atmos.plugins.cloud_render.light import sun_light, unit_direction
from atmos.shading.medium import source_reference


def column(I) -> tuple[np.ndarray, np.ndarray]:
    """far.glsl's far_column: (top, density factor) of a column ``I`` (profile units)."""
    I = np.asarray(I, np.float64)
    x = np.where(I >= 0.5 * FAR_TOP_SOFT, I + 0.5 * FAR_TOP_SOFT, np.sqrt(2.0 * FAR_TOP_SOFT * np.maximum(I, 0.0)))
    return np.where(I > FAR_MAX, 1.0, FAR_BASE + x), np.maximum(I / FAR_MAX, 1.0)


def profile(h, I) -> np.ndarray:
    """far.glsl's far_profile: the vertical profile at height fraction ``h`` of a column ``I``."""
    h, I = np.asarray(h, np.float64), np.asarray(I, np.float64)
    top, factor = column(I)
    p = factor * np.clip((h - FAR_BASE) / FAR_BASE_SOFT + 0.5, 0, 1) * np.clip((top - h) / FAR_TOP_SOFT, 0, 1)
    return np.where(I > 0.0, p, 0.0)


def above(h, top) -> np.ndarray:
    """The profile's integral from ``h`` to ``top`` (far.glsl's far_above)."""
    x = np.maximum(np.asarray(top, np.float64) - h, 0.0)
    return np.where(x >= FAR_TOP_SOFT, x - 0.5 * FAR_TOP_SOFT, x * x / (2.0 * FAR_TOP_SOFT))


class FarField:
    """The far field's columns I (profile units) as a function of world xz at mip 0: the fbm
    (:func:`atmos.plugins.cloud_far_field.reference.field_fbm` of ``octaves``, ``offsets``,
    ``tile_size``) ranked among the layer's ``quantiles`` (level 0), the volume's column sum at that
    rank (``columns``: its QUANTILES column-sum quantiles in cells, FarFieldLayer.read_cover) times
    ``amount`` (far.py far_amount); ``light_step_m`` the channels' spacing toward the sun (m)."""

    def __init__(self, light_step_m: float, *, octaves, offsets, tile_size: float, quantiles, columns, amount: float):
        self.light_step_m, self.amount = float(light_step_m), float(amount)
        self.field = dict(octaves=octaves, offsets=offsets, tile_size=tile_size)
        self.quantiles, self.columns = np.asarray(quantiles, np.float64), np.asarray(columns, np.float64)

    def column(self, xz) -> np.ndarray:
        rank = field_rank(field_fbm(xz, **self.field), self.quantiles)
        return self.amount * column_at_rank(rank, self.columns)

    def channels(self, xz, sun_dir) -> np.ndarray:
        """(..., 4): the column at xz and 1..3 light steps toward the sun (the baked channels)."""
        s = np.asarray(sun_dir, np.float64)[[0, 2]]
        n = np.linalg.norm(s)
        shift = s / n * self.light_step_m if n > 1e-6 else np.zeros(2)
        return np.stack([self.column(np.asarray(xz, np.float64) + k * shift) for k in range(4)], -1)


def far_source(field: FarField, medium, settings, p, dirs, band, sun) -> np.ndarray:
    """J (n, 3) at points ``p`` (n, 3) for view directions ``dirs``; ``band`` (base y, height)."""
    sun_dir = unit_direction(sun)
    c = field.channels(p[:, [0, 2]], sun_dir)
    h = (p[:, 1] - band[0]) / band[1]
    ds, per_step, rise = sun_steps(sun_dir, field.light_step_m, band[1])
    depth = np.zeros(len(p))
    for k in range(SUN_STEPS):
        x = (k + 0.5) * per_step
        i = min(int(x), 2)
        depth += profile(h + (k + 0.5) * rise, c[:, i] + (c[:, i + 1] - c[:, i]) * (x - i))
    T = np.exp(-medium.sigma_t * FAR_BODY * ds * depth)
    (top, factor), hb = column(c[:, 0]), np.maximum(h, FAR_BASE)
    k = medium.sigma_t * FAR_BODY * band[1] * factor
    up, down = k * above(hb, top), k * (above(FAR_BASE, top) - above(hb, top))
    sun_color, ambient = sun_light(sun)
    return source_reference(medium, settings, T, up, down, dirs @ sun_dir, dirs[:, 1], sun_color, ambient, sun_dir)


def far_march_reference(field: FarField, medium, settings, band, camera, sun, size) -> dict:
    """The march of the far field alone for rays that never meet the volume's footprint: from the
    near plane or the band's entry to its exit or ``settings.far_distance``, steps ``step_base +
    far_step_growth · s`` (``step_base`` = ``settings.step`` × ``medium``'s smallest cell), midpoint
    samples. Returns ``light`` (h, w, 3), ``alpha`` (h, w), ``distance`` (h, w): a·distance."""
    dirs, start = rays(camera, size)
    h, w = start.shape
    dirs, start = dirs.reshape(-1, 3), start.reshape(-1)
    pos = np.asarray(camera.position, np.float64)
    dy = np.where(np.abs(dirs[:, 1]) < 1e-12, 1e-12, dirs[:, 1])
    b0, b1 = (band[0] - pos[1]) / dy, (band[0] + band[1] - pos[1]) / dy
    enter = np.maximum(np.minimum(b0, b1), start)
    leave = np.minimum(np.maximum(b0, b1), settings.far_distance)
    step_base = settings.step * float(np.min(medium.cell_size))

    def sample(i, p):
        rho = FAR_BODY * profile((p[:, 1] - band[0]) / band[1], field.column(p[:, [0, 2]]))
        return rho, far_source(field, medium, settings, p, dirs[i], band, sun)

    return integrate(pos, dirs, enter, leave, settings.steps, step_base, settings.far_step_growth,
                     settings.min_transmittance, medium.sigma_t, sample, (h, w))
