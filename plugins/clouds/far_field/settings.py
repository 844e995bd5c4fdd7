"""CloudFarFieldSettings: the far field's look, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

from operator import attrgetter

from dataclasses import dataclass

from atmos.checks import CheckedSettings, bool_field, int_field, num_field, vec_field

TEXTURE_SETTINGS = ("size", "base_frequency", "seed", "light_step")   # changing one re-bakes the octaves
_TEXTURE_KEY = attrgetter(*TEXTURE_SETTINGS)


@dataclass(frozen=True)
class CloudFarFieldSettings(CheckedSettings):
    """The cloud layer beyond the simulated volume (:mod:`atmos.plugins.clouds.far_field`; all live).

    Its cover follows the simulation's (the volume's columns, measured on the GPU each frame), and so
    does its opacity: a point whose fbm has rank r in the layer gets the volume's column sum at the
    same rank (its edge-weighted column-sum quantiles), vertical optical depth τ = thickness · sigma_t ·
    cell height · that sum, seen along the view's slant (α = 1 − exp(−τ / |dir.y|), capped near the
    horizon). Its light comes from the cloud medium's own model (``clouds/volume/volume.glsl``) with
    the volume's own light at the same rank (:mod:`.rank_light`: its columns' sun transmittances and
    diffusion field, and the drawing renderer's octaves); the ground shadows
    (:mod:`atmos.plugins.clouds.shadows`) and light shafts take the same column beyond the volume.
    """

    thickness: float = num_field(1.0, 0.0, 1e3, "a scale on the layer's opacity (τ above); 0: no far field")
    tile_size: float | None = num_field(None, 1.0, 1e7, "m of one tile (:mod:`.pattern`: the octaves repeat "
                                        "every 1–4.2 tiles, each on its own turned axes, so the sum never "
                                        "repeats); None: chosen each frame (followed over a few seconds) so that "
                                        "the cover changes along a line as often per metre as the volume's "
                                        "measured cover does (cover.comp)", optional=True)
    wind: tuple | None = vec_field(None, 2, doc="(x, z) m/s the pattern drifts at with the App clock; None: it "
                                   "moves with the simulated clouds (the distance the weather's wind has carried "
                                   "them, ``CloudSets.wind_travel``), so volume and far field drift together",
                                   optional=True)
    horizon_fade: float = num_field(0.015, 0.0, 1.0, "it fades in while the view ray's height rises from 0 to "
                                    "this (sin of the elevation)", lo_open=True)
    size: int = int_field(256, 16, 2048, "the octave textures' size "
                          "(:class:`atmos.tile_octaves.OctaveTextures`; a change re-bakes them)")
    base_frequency: int = int_field(4, 1, 64, "the octave textures' base frequency (a change re-bakes them)")
    seed: int = int_field(0, 0, 2**32 - 1, "the octave textures' seed (a change re-bakes them)")
    light_step: float = num_field(0.01, 0.0, 0.25, "tiles: the relief's samples lie 2 of these toward the sun "
                                  "and away from it (:mod:`.pattern` CHANNEL_STEPS), so the lit sides of far "
                                  "clouds face the sun; 0: no relief (a change re-bakes the octaves)")
    animate: bool = bool_field(True, "False holds the pattern still")
    enabled: bool = bool_field(True, "False draws nothing")

    def texture_key(self) -> tuple:
        """The settings the baked octave textures depend on (what ``OctaveTextures`` asks of its settings)."""
        return _TEXTURE_KEY(self)
