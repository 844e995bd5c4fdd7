"""float64 numpy reference of the march's volumetric far field (``shaders/clouds/raymarch/far.glsl`` in
``march.glsl`` with FAR_FIELD): the profile, its light, and the march of rays that stay outside the
volume's footprint (far weight 1; mip 0 of the far field's textures, detail noise off, midpoints)."""
from __future__ import annotations

import numpy as np

from atmos.plugins.clouds.far_field.reference import column_at_rank, far_relief, field_fbm, field_rank, relief_light
from atmos.plugins.clouds.raymarch.reference import integrate, rays, tallest_type
from atmos.plugins.clouds.volume.shape import march_top, type_at, type_density
from atmos.plugins.clouds.volume.light import cell_tau, layer_sun, sun_source_at, unit_direction
from atmos.plugins.clouds.light.diffusion import field_radiance
from atmos.plugins.clouds.light.medium import OCTAVES, octave_parameters, source_reference


def sample_profile(profile, rank, h) -> np.ndarray:
    """far.glsl's textureLod(far_profile, (rank, h)): ``profile`` (intervals, heights, channels)
    (FarFieldLayer.read_profile: (R, G); RankLight's field_profile: (phi, F)) bilinear, texel (k, j)
    centred at ((k + 0.5)/intervals, (j + 0.5)/heights), clamped to the edge; returns (..., channels)."""
    table = np.asarray(profile, np.float64)
    n, m = table.shape[:2]
    rank, h = np.broadcast_arrays(np.asarray(rank, np.float64), np.asarray(h, np.float64))

    def axis(x, size):
        p = np.clip(x * size - 0.5, 0.0, size - 1.0)
        i0 = np.minimum(np.floor(p).astype(np.int64), max(size - 2, 0))
        return i0, np.minimum(i0 + 1, size - 1), (p - i0)[..., None]

    (k0, k1, fk), (j0, j1, fj) = axis(rank, n), axis(h, m)
    low = (1 - fk) * table[k0, j0] + fk * table[k1, j0]
    high = (1 - fk) * table[k0, j1] + fk * table[k1, j1]
    return (1 - fj) * low + fj * high


class FarField:
    """The far field as a function of world xz at mip 0: the fbm
    (:func:`atmos.plugins.clouds.far_field.reference.field_fbm` of ``octaves``, ``offsets``,
    ``tile_size``) ranked among the layer's ``quantiles`` (level 0); a point of rank r holds the
    volume's column sum at r (``columns``: its QUANTILES column-sum quantiles in cells,
    FarFieldLayer.read_cover) spread over height by ``profile`` (FarFieldLayer.read_profile), its
    channels (the relief's samples) read from the textures' own; ``sun_profile``: the volume's mean octave
    sun transmittances by rank and height (RankLight.read()["sun_profile"]); ``field_profile``: the
    diffusion field's mean (phi, F) likewise (RankLight.read()["field_profile"]; None: no field)."""

    def __init__(self, *, octaves, offsets, tile_size: float, quantiles, columns, profile, sun_profile,
                 field_profile=None):
        self.field = dict(octaves=octaves, offsets=offsets, tile_size=tile_size)
        self.quantiles, self.columns = np.asarray(quantiles, np.float64), np.asarray(columns, np.float64)
        self.profile = np.asarray(profile, np.float64)
        self.sun_profile = np.asarray(sun_profile, np.float64)
        self.field_profile = None if field_profile is None else np.asarray(field_profile, np.float64)

    def rank(self, xz, channel: int = 0) -> np.ndarray:
        return field_rank(field_fbm(xz, **self.field, channel=channel), self.quantiles)

    def density(self, rank, h, cloud_type=None, ny: float = 1.0) -> np.ndarray:
        """far.glsl's far_density: the column sum at ``rank`` × the profile's R at height fraction ``h``;
        with a ``cloud_type`` (one, or one per point), :func:`~atmos.plugins.clouds.volume.shape.type_density` of the column
        sum / ``ny`` (the layer's height in cells)."""
        h = np.asarray(h, np.float64)
        if cloud_type is not None:
            return type_density(column_at_rank(rank, self.columns) / ny, h, cloud_type)
        d = column_at_rank(rank, self.columns) * sample_profile(self.profile, rank, h)[..., 0]
        return np.where((h >= 0.0) & (h <= 1.0), d, 0.0)

    def channels(self, xz) -> np.ndarray:
        """(..., 4): far_ranks, the ranks of the four baked channels at xz (pattern.CHANNEL_STEPS)."""
        return np.stack([self.rank(xz, k) for k in range(4)], -1)


def far_source(field: FarField, medium, settings, p, dirs, band, sun, albedo=None, ground_sun: float = 1.0) -> np.ndarray:
    """J (n, 3) at points ``p`` (n, 3) for view directions ``dirs``; ``band`` (base y, height); ``albedo``,
    ``ground_sun``: the ground below (:func:`atmos.plugins.clouds.light.medium.environment`)."""
    sun_dir = unit_direction(sun)
    c = field.channels(p[:, [0, 2]])
    h01 = np.clip((p[:, 1] - band[0]) / band[1], 0.0, 1.0)
    exponents = np.ones(OCTAVES)
    exponents[-1] = octave_parameters(settings.octaves, medium)[0]  # volume.glsl's octave_exponents
    relief = far_relief(c, field.columns, cell_tau(medium), float(sun_dir[1]))
    octaves = relief_light(sample_profile(field.sun_profile, c[:, 0], h01), relief[:, None] * exponents)
    column = cell_tau(medium) * column_at_rank(c[:, 0], field.columns)
    above = sample_profile(field.profile, c[:, 0], h01)[..., 1]
    up, down = column * above, column * (1.0 - above)
    top = march_top(tallest_type(settings))                  # a cloud type's towers take their own heights' sun
    by_height, sun_color, ambient = layer_sun(sun, (band[0], band[0] + band[1]), top)
    h_sun = np.clip((p[:, 1] - band[0]) / band[1], 0.0, top)
    diffusion = None
    if field.field_profile is not None and settings.ms_diffusion > 0:       # the volume's field at this rank
        values = sample_profile(field.field_profile, c[:, 0], h01)
        diffusion = field_radiance(values, dirs, medium.phase.lobes, sun_dir)
    return source_reference(medium, settings, None, up, down, dirs @ sun_dir, dirs[:, 1], sun_color, ambient, sun_dir,
                            diffusion, octaves=octaves, sun_colors=sun_source_at(by_height, h_sun, top), albedo=albedo,
                            ground_sun=ground_sun)


def far_march_reference(field: FarField, medium, settings, band, camera, sun, size, albedo=None,
                        ground_sun: float = 1.0) -> dict:
    """The march of the far field alone for rays that never meet the volume's footprint: from the
    near plane or the band's entry to its exit or ``settings.far_distance``, steps ``step_base +
    far_step_growth · s`` (``step_base`` = ``settings.step`` × ``medium``'s smallest cell), midpoint
    samples (``albedo``, ``ground_sun``: :func:`far_source`'s). Returns ``light`` (h, w, 3), ``alpha`` (h, w),
    ``distance`` (h, w): a·distance."""
    dirs, start = rays(camera, size)
    h, w = start.shape
    dirs, start = dirs.reshape(-1, 3), start.reshape(-1)
    pos = np.asarray(camera.position, np.float64)
    dy = np.where(np.abs(dirs[:, 1]) < 1e-12, 1e-12, dirs[:, 1])
    top = march_top(tallest_type(settings))                  # towers raise the band's top
    b0, b1 = (band[0] - pos[1]) / dy, (band[0] + top * band[1] - pos[1]) / dy
    enter = np.maximum(np.minimum(b0, b1), start)
    leave = np.minimum(np.maximum(b0, b1), settings.far_distance)
    step_base = settings.step * float(np.min(medium.cell_size))

    def sample(i, p):
        rho = field.density(field.rank(p[:, [0, 2]]), (p[:, 1] - band[0]) / band[1],
                            type_at(settings.cloud_type, settings.type_map, p[:, 0], p[:, 2]),
                            band[1] / float(medium.cell_size[1]))
        return rho, far_source(field, medium, settings, p, dirs[i], band, sun, albedo, ground_sun)

    return integrate(pos, dirs, enter, leave, settings.steps, step_base, settings.far_step_growth,
                     settings.min_transmittance, medium.sigma_t, sample, (h, w))
