"""CloudFarFieldSettings: the far field's look, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_bool, check_int, check_num, check_vec

_OWNER = "CloudFarFieldSettings"
TEXTURE_SETTINGS = ("size", "base_frequency", "seed", "light_step")   # changing one re-bakes the octaves


@dataclass(frozen=True)
class CloudFarFieldSettings(CheckedSettings):
    """The cloud layer beyond the simulated volume (:mod:`atmos.plugins.clouds.far_field`).

    Its cover follows the simulation's (the volume's columns, measured on the GPU each frame).
    ``thickness``: a scale (default 1) on the layer's opacity, which comes from the volume: a
    point whose fbm has rank r in the layer gets the volume's column sum at the same rank (its
    edge-weighted column-sum quantiles), vertical optical depth τ = thickness · sigma_t · cell height ·
    that sum, seen along the view's slant (α = 1 − exp(−τ / |dir.y|), capped near the horizon); 0: no far field.
    Its light comes from the cloud medium's own model (``clouds/volume/volume.glsl``) with the volume's own
    light at the same rank (:mod:`.rank_light`: its columns' sun transmittances and diffusion field, and
    the drawing renderer's octaves); the ground shadows (:mod:`atmos.plugins.clouds.shadows`)
    and light shafts take the same column beyond the volume. ``tile_size``: None (the default) sizes the clouds
    from the volume's: the tile is chosen each frame (followed over a few seconds) so that the far field's
    cover changes along a line as often per metre as the volume's measured cover does (cover.comp); a
    number fixes the metres of one tile (:mod:`.pattern`: the octaves repeat every 1–4.2 tiles, each on
    its own turned axes, so the sum never repeats); ``wind``: None (the default) moves the pattern with the
    simulated clouds (the distance the weather's wind has carried them, ``CloudSets.wind_travel``),
    so volume and far field drift together; an (x, z) tuple drifts it at that many m/s with the App
    clock instead. ``animate`` False holds it still. ``horizon_fade``: it fades in while the view ray's
    height rises from 0 to this (sin of the elevation). ``size``, ``base_frequency``, ``seed``,
    ``light_step``: the octave textures (:class:`atmos.plugins.sky_layer.octaves.OctaveTextures`;
    ``light_step`` (tiles): the relief's samples lie 2 of these toward the sun and away from it
    (:mod:`.pattern` CHANNEL_STEPS): the lit sides of far clouds face the sun; 0: no relief).
    ``enabled`` False draws nothing.
    """

    thickness: float = 1.0
    tile_size: float | None = None
    wind: tuple | None = None
    horizon_fade: float = 0.015
    size: int = 256
    base_frequency: int = 4
    seed: int = 0
    light_step: float = 0.01
    animate: bool = True
    enabled: bool = True

    def __post_init__(self):
        o = _OWNER
        self.store(dict(
            thickness=check_num(o, "thickness", self.thickness, 0.0, 1e3),
            tile_size=check_num(o, "tile_size", self.tile_size, 1.0, 1e7, optional=True),
            wind=check_vec(o, "wind", self.wind, 2, optional=True),
            horizon_fade=check_num(o, "horizon_fade", self.horizon_fade, 0.0, 1.0, lo_open=True),
            size=check_int(o, "size", self.size, 16, 2048),
            base_frequency=check_int(o, "base_frequency", self.base_frequency, 1, 64),
            seed=check_int(o, "seed", self.seed, 0, 2**32 - 1),
            light_step=check_num(o, "light_step", self.light_step, 0.0, 0.25),
            animate=check_bool(o, "animate", self.animate),
            enabled=check_bool(o, "enabled", self.enabled),
        ))

    def texture_key(self) -> tuple:
        """The settings the baked octave textures depend on (what ``OctaveTextures`` asks of its settings)."""
        return tuple(getattr(self, name) for name in TEXTURE_SETTINGS)
