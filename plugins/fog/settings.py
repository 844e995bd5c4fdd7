"""FogSettings: every knob of the fog post-process, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_int, check_vec, choice_field, int_field, nested_field, num_field, vec_field
from atmos.phase import Phase

MODES = {"linear": 0, "exp": 1, "exp2": 2, "hetero_exp": 3, "hetero_exp2": 4, "height": 5, "hetero_height": 6}
HETEROGENEOUS = ("hetero_exp", "hetero_exp2", "hetero_height")
ALIASES = {"exponential": "exp", "exp_squared": "exp2", "squared_exponential": "exp2",
           "heterogeneous_exp": "hetero_exp", "heterogeneous_exp2": "hetero_exp2"}
NOISES = ("texture", "procedural")
SKIES = ("fog", "keep")
COLOR_SOURCES = ("fixed", "sky")
MAX_TEXELS = 256          # largest noise volume edge (resolution * texels_per_cell)
PAPER_RESOLUTIONS = {"fine": (16, 32, 64, 128), "coarse": (8, 16, 32, 64)}
DEFAULT_WINDS = ((1.5, 0.0, 0.5), (-1.0, 0.1, 1.2), (0.8, -0.05, -1.6), (-2.0, 0.0, -0.7))
GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))
_OWNER = "FogSettings"


@dataclass(frozen=True)
class FogSettings(CheckedSettings):
    """Distance fog as a post-process: the colour fades toward the fog colour by a fog factor of the
    distance. The heterogeneous modes scale g by ``octaves`` of periodic gradient noise, octave i with
    ``resolutions[i]`` lattice cells per ``tile_size`` metres, displaced by ``winds[i]`` m/s and turned
    about y by i golden angles. Clouds that give their own distance (:mod:`atmos.composition`) are
    fogged by it. Every field is live: ``FogPlugin.configure`` changes it on the next frame (the pass
    fetches the program variant and noise volumes it needs). Three fields are checked by hand (not in
    the list below):

    ``mode`` = 'exp2': the fog factor: 'linear', 'exp', 'exp2', 'hetero_exp' (eq. 6), 'hetero_exp2'
    (eq. 7), or 'height': density g e^(-(y - height_base) / scale_height), thick in valleys and thin
    above (its optical depth along each ray in closed form), 'hetero_height' the same with the noise;
    the aliases in ALIASES are resolved. 'linear' needs start < end.
    ``resolutions`` = (16, 32, 64, 128): octaves to 4 whole numbers, each 2..MAX_TEXELS // texels_per_cell
    (PAPER_RESOLUTIONS: 'fine' or 'coarse').
    ``winds`` = DEFAULT_WINDS: 4 (x, y, z) velocities in m/s, one per octave.
    """

    mode: str = "exp2"
    density: float = num_field(0.044, 0.0, doc="g, per metre (exp, exp2, height and the heterogeneous modes; "
                               "height: at height_base)")
    fog_color: tuple = vec_field((0.8, 0.8, 0.8), 3, "non-negative", "linear RGB the colour fades toward")
    start: float = num_field(0.0, doc="metres: linear fog begins here")
    end: float = num_field(100.0, doc="metres: linear fog is full here")
    sky: str = choice_field("fog", SKIES, "fog: sky pixels are fogged as at the far distance; keep: left to "
                            "the sky")
    octaves: int = int_field(4, 1, 4, "heterogeneous modes: noise octaves")
    resolutions: tuple = PAPER_RESOLUTIONS["fine"]
    winds: tuple = DEFAULT_WINDS
    tile_size: float = num_field(256.0, 0.0, doc="metres the noise lattice repeats over", lo_open=True)
    amplitude: float = num_field(1.0, 0.0, 1.0, "the grey-scale range of an octave")
    noise: str = choice_field("texture", NOISES, "texture: GPU-made tileable 3D textures of resolution × "
                              "texels_per_cell texels, trilinear; procedural: the same noise evaluated per pixel")
    texels_per_cell: int = int_field(1, 1, MAX_TEXELS, "texture noise: texels per lattice cell")
    seed: int = int_field(0, 0, 2**32 - 1, "picks the lattice gradients")
    time_offset: float = num_field(0.0, doc="seconds added to the noise animation clock")
    color_from: str = choice_field("fixed", COLOR_SOURCES, "fixed: fog toward fog_color; sky: toward fog_color ⊙ "
                                   "the sky's horizon radiance in the pixel's azimuth (aerial perspective, "
                                   ":mod:`atmos.plugins.fog.sky_color`; fog_color=(1, 1, 1) for the sky's own "
                                   "colour)")

    height_base: float = num_field(0.0, doc="height modes: world y (m) where the density is g")
    scale_height: float = num_field(50.0, 0.0, doc="height modes: metres over which the density falls by e",
                                    lo_open=True)
    sun_scattering: float = num_field(0.0, 0.0, 100.0, "sunlight the fog scatters toward the eye: "
                                      "sun_scattering × Sun.color × 4π p(θ) with the fog's phase, θ between the "
                                      "view ray and the sun, faded out as the sun sets (0: none, no shader code)")
    phase: Phase = nested_field(Phase(0.7, -0.2, 0.1), "the fog droplets' phase function (with sun_scattering): "
                                "bright toward the sun")

    @property
    def heterogeneous(self) -> bool:
        return self.mode in HETEROGENEOUS

    @property
    def turns(self) -> tuple:
        """The octaves' turn angles about y (radians)."""
        return tuple(i * GOLDEN_ANGLE for i in range(4))

    def __post_init__(self):
        """The declared checks, then mode (its aliases resolved), start < end for linear fog, resolutions
        and winds (normalised)."""
        given = self.start, self.end            # as given, for the message
        super().__post_init__()
        o = _OWNER
        mode = ALIASES.get(self.mode, self.mode) if isinstance(self.mode, str) else self.mode
        if mode not in MODES:
            raise ValueError(f"{o}.mode must be one of {', '.join(MODES)} (aliases: {', '.join(ALIASES)}), "
                             f"got {self.mode!r}")
        if mode == "linear" and not self.start < self.end:
            raise ValueError(f"{o}.start must be < end for linear fog, got start={given[0]!r}, end={given[1]!r}")
        octaves, tpc = self.octaves, self.texels_per_cell
        try:
            resolutions = () if isinstance(self.resolutions, str) else tuple(self.resolutions)
        except TypeError:
            resolutions = ()
        if not octaves <= len(resolutions) <= 4:
            raise ValueError(f"{o}.resolutions must be {octaves} to 4 whole numbers (one per octave; octaves="
                             f"{octaves}), got {self.resolutions!r}")
        try:
            winds = () if isinstance(self.winds, str) else tuple(self.winds)
        except TypeError:
            winds = ()
        if len(winds) != 4:
            raise ValueError(f"{o}.winds must be 4 (x, y, z) velocities in m/s (one per octave), got {self.winds!r}")
        self.store(dict(
            mode=mode,
            resolutions=tuple(check_int(o, f"resolutions[{i}]", r, 2, MAX_TEXELS // tpc)
                              for i, r in enumerate(resolutions)),
            winds=tuple(check_vec(o, f"winds[{i}]", w, 3) for i, w in enumerate(winds)),
        ))
