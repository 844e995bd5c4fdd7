"""The light both cloud renderers share (``clouds/volume/volume.glsl``; the model is
:mod:`atmos.plugins.clouds.light.medium`): the sun's colour faded across the horizon and over the layer's height,
and the uniforms of J."""
from __future__ import annotations

import math
import struct
from operator import is_
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, num_field
from atmos.gpu.uniforms import write_block, write_uniforms
from atmos.lighting import Sun
from atmos.plugins.clouds.light.medium import field_weight, ground_parts, octave_parameters

DEFAULT_AMBIENT = (0.35, 0.47, 0.65)
DEFAULT_OCTAVES = (None, 0.9525, None)    # a, b, c of the octaves: a and c follow the medium (medium.octave_parameters), b fitted
DEFAULT_DIFFUSION = 0.575                 # the diffusion field's weight beta, fitted with b (bench_cloud_light --fit-grid)
SUN_HEIGHTS = 5                           # volume.glsl's samples of the sun's colour over the layer, base to top (2: the middle)


@dataclass(frozen=True)
class CloudLightSettings(CheckedSettings):
    """The multiple-scattering octaves both cloud renderers share (the sprites' CloudRenderSettings
    and the march's RaymarchCloudSettings inherit them; :mod:`atmos.plugins.clouds.light.medium`), and
    the weight of the diffusion field beside them. By default a and c follow the medium's phase (and every
    octave its albedo: :func:`atmos.plugins.clouds.light.medium.octave_parameters`); b and beta are the
    search ``benchmarks/bench_cloud_light.py --fit-grid`` found against the path tracer (README "Cloud
    light"). The 2D far
    field is lit with the drawing renderer's settings (``CloudFarFieldPlugin.light_settings``). A
    subclass declares its own fields after these four; ``CheckedSettings.__post_init__`` checks all of
    them, naming the subclass."""
    ms_attenuation: float | None = num_field(DEFAULT_OCTAVES[0], 0.0, 1.0, "a: the share of scatterings that turn "
                                             "light aside (the octaves' Poisson mean (1 - a) tau); None: from the "
                                             "phase, 1 - g_mean (medium.phase_octaves)", optional=True)
    ms_contribution: float = num_field(DEFAULT_OCTAVES[1], 0.0, 1.0, "b: octave i's weight b^i")
    ms_eccentricity: float | None = num_field(DEFAULT_OCTAVES[2], 0.0, 1.0, "c: octave i's lobes c^i g; None: "
                                              "the phase's g (octave i's lobe g^(i+1))", optional=True)
    ms_diffusion: float = num_field(DEFAULT_DIFFUSION, 0.0, 2.0, "the weight beta of the diffusion field, the "
                                    "light turned aside (:mod:`atmos.plugins.clouds.light.diffusion`: J += "
                                    "sun_source beta max(phi - 3 g F.ray, -cos 2 H phi, 0) / 4pi, cos = ray . sun); "
                                    "0 turns the term off (and, with no other reader, the field's solve: "
                                    "``plugins/clouds/volume/field_demand.py``)")

    @property
    def octaves(self) -> tuple:
        """(a, b, c): what :func:`light_uniforms` and ``bind_volume`` take."""
        return self.ms_attenuation, self.ms_contribution, self.ms_eccentricity


def sun_light(sun: Sun | None, altitude: float | None = None) -> tuple[tuple, tuple]:
    """(sun colour, ambient) as float tuples. With an ``altitude`` (m) and a sky that gives the sun's
    colour by altitude (``Sun.color_by_altitude``), the colour there (the planet's shadow included: a
    cloud layer keeps its sun after the ground's sunset); else ``Sun.color``, faded to 0 across the
    horizon (direction y from −0.01 to 0.01), so a sun below it leaves ambient light only."""
    sun = sun or Sun()
    if altitude is not None and sun.color_by_altitude is not None:
        ambient = tuple(float(c) for c in getattr(sun, "ambient", DEFAULT_AMBIENT))
        return tuple(float(c) for c in sun.color_at(altitude)), ambient
    direction = np.asarray(sun.direction, np.float64)
    norm = math.sqrt(direction.dot(direction))   # np.linalg.norm's own formula (1-D float64), without its overhead
    y = direction[1] / norm if norm > 0 and np.isfinite(norm) else -1.0
    x = min(max((y + 0.01) / 0.02, 0.0), 1.0)
    fade = x * x * (3.0 - 2.0 * x)
    color = tuple(float(c) * fade for c in sun.color)
    ambient = tuple(map(float, getattr(sun, "ambient", DEFAULT_AMBIENT)))
    return color, ambient


def sun_colors(sun: Sun | None, layer=None) -> np.ndarray:
    """(SUN_HEIGHTS, 3) float64: the sun's colour (:func:`sun_light`) at the heights ``base + k / 4 (top −
    base)`` of ``layer`` = (base, top) world y (m), what volume.glsl's ``sun_sources`` hold (× albedo ×
    intensity); ``layer`` None: the camera's colour at every height."""
    sun = sun or Sun()
    if layer is None or sun.color_by_altitude is None:
        return np.tile(np.asarray(sun_light(sun)[0], np.float64), (SUN_HEIGHTS, 1))
    base, top = map(float, layer)
    return sun.color_at(base + np.arange(SUN_HEIGHTS) / (SUN_HEIGHTS - 1) * (top - base))


def layer_sun(sun: Sun | None, layer=None, span: float = 1.0) -> tuple[np.ndarray, np.ndarray, tuple]:
    """(the sun's colours at the layer's heights (:func:`sun_colors`; over ``span`` layer heights from its
    base: a cloud type's towers), the middle's of the layer itself (the ground's light takes it), the
    ambient): the sun every cloud renderer and reference lights a layer with."""
    colors = sun_colors(sun, layer)
    middle = colors[SUN_HEIGHTS // 2]
    if span != 1.0 and layer is not None:
        base, top = map(float, layer)
        colors = sun_colors(sun, (base, base + span * (top - base)))
    return colors, middle, sun_light(sun)[1]


def sun_source_at(sources, v, span: float = 1.0) -> np.ndarray:
    """(..., 3) float64: volume.glsl's ``sun_source_at`` of the (SUN_HEIGHTS, 3) ``sources`` (spanning
    ``span`` layer heights) at height fractions ``v`` (...,) of the layer (0 base, 1 top; clamped to the
    span), linear between the samples."""
    s = np.asarray(sources, np.float64)
    x = np.clip(np.asarray(v, np.float64) / max(span, 1.0), 0.0, 1.0) * (len(s) - 1)
    k = np.minimum(x.astype(np.int64), len(s) - 2)
    f = (x - k)[..., None]
    return s[k] * (1.0 - f) + s[k + 1] * f


def unit_direction(sun: Sun | None) -> np.ndarray:
    d = np.asarray((sun or Sun()).direction, np.float64)
    n = math.sqrt(d.dot(d))   # np.linalg.norm's own formula (1-D float64), without its overhead
    return d / n if n > 0 and np.isfinite(n) else np.array([0.0, -1.0, 0.0])


def cell_tau(cloud_settings) -> float:
    """sigma_t × cell height: the optical depth of one cell of density 1, vertically (volume.glsl's
    column_tau; the far field's columns per summed cell)."""
    return float(cloud_settings.sigma_t * cloud_settings.cell_size[1])


def light_uniforms(cloud_settings, sun: Sun | None, octaves=DEFAULT_OCTAVES, diffusion: float = 0.0,
                   layer=None, ground=None, span: float = 1.0) -> dict:
    """The light uniforms of ``volume.glsl`` for a ``CloudSettings`` medium, the ``Sun``, the
    multiple-scattering octaves (a, b, c), the diffusion field's weight beta (scaled by the medium:
    ``medium.field_weight``) and the layer (base, top) world
    y (m) over which the clouds take the sun's colour (``sun_sources``: :func:`sun_colors`; the ground's
    light takes the middle's; None: the camera's colour everywhere; ``span``: the colours reach that many
    layer heights up, for a cloud type's towers) and the ``ground``'s albedo (RGB; None: the medium's
    ``ground_albedo``). The last few results are kept,
    keyed by the identity of the settings, the Sun and its (immutable, assigned-anew) fields and by
    the values of the rest: every renderer of a frame asks for the same."""
    sun = sun or Sun()
    key = (cloud_settings, sun, sun.direction, sun.color, sun.ambient, sun.color_by_altitude)
    rest = (tuple(octaves), diffusion, None if layer is None else tuple(layer), None if ground is None else tuple(ground),
            span)
    for held, held_rest, values in _LIGHT_MEMO:
        if held_rest == rest and all(map(is_, held, key)):
            return dict(values)
    values = _light_uniforms(cloud_settings, sun, octaves, diffusion, layer, ground, span)
    _LIGHT_MEMO.insert(0, (key, rest, values))
    del _LIGHT_MEMO[4:]
    return dict(values)


_LIGHT_MEMO: list = []      # (identities, values, uniforms), newest first


def _light_uniforms(cloud_settings, sun: Sun, octaves, diffusion: float, layer, ground, span: float = 1.0) -> dict:
    colors, middle, ambient = layer_sun(sun, layer, span)
    direction = unit_direction(sun)
    lit, sky_lit = ground_parts(cloud_settings, middle, ambient, direction, ground)
    s = cloud_settings
    sources = s.albedo * s.sun_intensity * colors
    sky = s.sky_intensity * np.asarray(ambient, np.float64)
    return {"sun_sources": [tuple(row) for row in np.asarray(sources, np.float64).tolist()],
            "sky_source": tuple(map(float, 0.5 * s.albedo * sky)),
            "ground_sky_source": tuple(map(float, 0.5 * s.albedo * sky_lit)),
            "ground_sun_source": tuple(map(float, 0.5 * s.albedo * lit)),
            "sun_dir": tuple(map(float, direction)),
            "sun_span": float(span),
            "phase_lobes": s.phase.lobes,
            "outward_share": float(s.phase.hemisphere_share),
            "ms_octaves": octave_parameters(octaves, s),
            "column_tau": cell_tau(s),
            "albedo": float(s.albedo),
            "ms_diffusion": field_weight(diffusion, octaves, s)}


LIGHT_BLOCK, LIGHT_BINDING = "CloudLight", 2      # volume.glsl's block of the light that changes with the sun
LIGHT_MEMBERS = ("sun_sources", "sky_source", "ground_sky_source", "ground_sun_source", "sun_dir", "sun_span")


def pack_light(values: dict) -> bytes:
    """volume.glsl's CloudLight block (std140: vec3 sun_sources[SUN_HEIGHTS], sky_source, ground_sky_source,
    ground_sun_source, each in 16 bytes, then sun_dir and sun_span in 16) from :func:`light_uniforms`' ``values``."""
    rows = [*values["sun_sources"], *map(values.__getitem__, LIGHT_MEMBERS[1:5])]
    data = [c for row in rows for c in (*row, 0.0)]
    data[-1] = values.get("sun_span", 1.0)
    return struct.pack(f"<{len(data)}f", *data)


def write_light(program, values: dict, **more) -> None:
    """:func:`light_uniforms`' ``values`` (and ``more``) into ``program``: the sun's light into its
    CloudLight block (one buffer write when it changed), the rest as uniforms."""
    if write_block(program, LIGHT_BLOCK, LIGHT_BINDING, pack_light(values)):
        values = {k: v for k, v in values.items() if k not in LIGHT_MEMBERS}
    write_uniforms(program, values, **more)
