"""VolumetricFogSettings: every setting of the volumetric fog, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_bool, check_int, check_num, check_vec

MAX_OCTAVES = 16
MAX_STEPS = 1024
MAX_LIGHT_STEPS = 32
_OWNER = "VolumetricFogSettings"


@dataclass(frozen=True)
class VolumetricFogSettings(CheckedSettings):
    """The FBM medium, the march and the colours (world units are metres, y is up).

    density(p) = bias − falloff·‖(p − center)/scale‖ + fbm(frequency·(p − center − wind·t), octaves);
    extinction per metre = absorption · density where density > 0.
    """

    center: tuple = (0.0, 0.0, 0.0)
    scale: tuple = (2.0, 0.5, 2.0)             # stretches the envelope per axis
    bias: float = 0.1
    falloff: float = 0.05                      # 0: an unbounded medium (march to max_distance)
    frequency: float = 0.15                    # noise cells per metre at the first octave
    octaves: int = 6                           # 1..16
    seed: int = 0
    wind: tuple = (1.5, 0.0, 0.5)              # metres per second the noise drifts
    absorption: float = 0.12                   # extinction per metre at density 1
    steps: int = 48                            # 1..1024 view-ray samples
    light_steps: int = 4                       # 0..32 samples toward the sun
    light_step: float = 3.0                    # metres between light samples
    max_distance: float = 400.0
    ambient: tuple = (0.45, 0.52, 0.62)        # ambient radiance the fog scatters
    scattering: tuple = (1.0, 0.7, 0.4)        # colour of scattered sunlight (times the sun colour)
    animate: bool = True                       # drift with the App clock (False: frozen at time 0)

    def __post_init__(self):
        o = _OWNER
        checked = dict(
            center=check_vec(o, "center", self.center, 3),
            scale=check_vec(o, "scale", self.scale, 3, "positive"),
            wind=check_vec(o, "wind", self.wind, 3),
            ambient=check_vec(o, "ambient", self.ambient, 3, "non-negative"),
            scattering=check_vec(o, "scattering", self.scattering, 3, "non-negative"),
            bias=check_num(o, "bias", self.bias),
            falloff=check_num(o, "falloff", self.falloff, 0.0),
            frequency=check_num(o, "frequency", self.frequency, 0.0, lo_open=True),
            absorption=check_num(o, "absorption", self.absorption, 0.0),
            light_step=check_num(o, "light_step", self.light_step, 0.0, lo_open=True),
            max_distance=check_num(o, "max_distance", self.max_distance, 0.0, lo_open=True),
            octaves=check_int(o, "octaves", self.octaves, 1, MAX_OCTAVES),
            steps=check_int(o, "steps", self.steps, 1, MAX_STEPS),
            light_steps=check_int(o, "light_steps", self.light_steps, 0, MAX_LIGHT_STEPS),
            seed=check_int(o, "seed", self.seed, 0, 2**32 - 1),
            animate=check_bool(o, "animate", self.animate),
        )
        self.store(checked)
