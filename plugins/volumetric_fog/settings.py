"""VolumetricFogSettings: every setting of the volumetric fog, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, bool_field, check_shape, choice_field, int_field, num_field, vec_field
from atmos.froxels import MAX_FROXELS, history_field

MAX_OCTAVES = 16
MAX_STEPS = 1024
MAX_LIGHT_STEPS = 32


@dataclass(frozen=True)
class VolumetricFogSettings(CheckedSettings):
    """The FBM medium, the march and the colours (world units are metres, y is up; all live).

    density(p) = bias − falloff·‖(p − center)/scale‖ + fbm(frequency·(p − center − wind·t), octaves);
    extinction per metre = absorption · density where density > 0.

    ``froxels`` = None (default): every pixel marches its own ray in ``steps`` samples (a compute pass);
    (W, H, D), each 1..256: a froxel volume instead — each of W × H columns marched once in D slices
    (even near the camera, logarithmic beyond max_distance / 32), every pixel reading it trilinearly:
    W·H·D samples instead of pixels × steps, softer detail (``benchmarks/bench_volumetric_fog.py``
    measures the error against a 256-step float64 march by size); each slice's sample moves every frame
    and the frames are averaged through reprojection (``froxel_history``).
    """

    center: tuple = vec_field((0.0, 0.0, 0.0), 3, doc="m, the centre of the medium's envelope")
    scale: tuple = vec_field((2.0, 0.5, 2.0), 3, "positive", "stretches the envelope per axis")
    bias: float = num_field(0.1, doc="the envelope's density at the centre (the noise is added to it)")
    falloff: float = num_field(0.05, 0.0, doc="density lost per unit of scaled distance from the centre "
                               "(0: an unbounded medium, marched to max_distance)")
    frequency: float = num_field(0.15, 0.0, doc="noise cells per metre at the first octave", lo_open=True)
    octaves: int = int_field(6, 1, MAX_OCTAVES, "FBM octaves")
    seed: int = int_field(0, 0, 2**32 - 1, "the noise's seed")
    wind: tuple = vec_field((1.5, 0.0, 0.5), 3, doc="metres per second the noise drifts")
    absorption: float = num_field(0.12, 0.0, doc="extinction per metre at density 1")
    steps: int = int_field(48, 1, MAX_STEPS, "view-ray samples")
    light_steps: int = int_field(4, 0, MAX_LIGHT_STEPS, "samples toward the sun")
    light_step: float = num_field(3.0, 0.0, doc="metres between light samples", lo_open=True)
    max_distance: float = num_field(400.0, 0.0, doc="m, the farthest the view ray is marched", lo_open=True)
    ambient: tuple = vec_field((0.45, 0.52, 0.62), 3, "non-negative", "ambient radiance the fog scatters")
    scattering: tuple = vec_field((1.0, 0.7, 0.4), 3, "non-negative", "colour of scattered sunlight (times "
                                  "the sun colour)")
    animate: bool = bool_field(True, "drift with the App clock (False: frozen at time 0)")
    ambient_from: str = choice_field("fixed", ("fixed", "sky"), "fixed: ambient × a day factor of the sun's "
                                     "height; sky: ambient ⊙ the App's sky's mean horizon radiance (a SkyPlugin's "
                                     "light at the camera's altitude: dawn-coloured at dawn, dark at night; "
                                     "ambient=(1, 1, 1) for the sky's own colour)")
    noise: str = choice_field("auto", ("auto", "filtered", "hash"), "the FBM's lattice (64 cells a side, "
                              "then it repeats; atmos.plugins.volumetric_fog.noise): filtered: baked once per "
                              "seed into a 3D texture, one trilinear fetch per octave (within "
                              "noise.filtered_error of the hashed FBM: the texture unit's blend weights); hash: "
                              "8 corners hashed per octave; auto: filtered on a GPU, hash on a software "
                              "renderer")
    cloud_shadows: bool = bool_field(True, "the clouds' shadows darken the fog's sunlight (their shadow map, one "
                                     "fetch per light sample); a scene without clouds has none to read")
    froxels: tuple | None = None
    froxel_history: float = history_field()

    def __post_init__(self):
        super().__post_init__()
        self.store(dict(froxels=check_shape(self.froxels, "VolumetricFogSettings.froxels", hi=MAX_FROXELS, optional=True)))
