"""FogSettings: every knob of the fog post-process, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_choice, check_int, check_num, check_vec

MODES = {"linear": 0, "exp": 1, "exp2": 2, "hetero_exp": 3, "hetero_exp2": 4}
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
    """Fog factor mode (``linear``, ``exp``, ``exp2``, ``hetero_exp`` = eq. 6, ``hetero_exp2`` = eq. 7),
    density g, linear ``start``/``end``, ``fog_color`` (linear RGB) and sky handling (``fog``: sky
    pixels are fogged as at the far distance; ``keep``: left to the sky).

    Heterogeneous modes: ``octaves`` (1-4) of periodic gradient noise, octave i with ``resolutions[i]``
    lattice cells per ``tile_size`` metres, displaced by ``winds[i]`` m/s and turned about y by i golden
    angles; ``noise`` is ``texture`` (GPU-made tileable 3D textures of resolution * texels_per_cell
    texels, trilinear) or ``procedural`` (the same noise evaluated per pixel); ``amplitude`` in [0, 1]
    is the grey-scale range of an octave; ``seed`` picks the lattice gradients. ``time_offset``
    (seconds) shifts the noise animation clock. ``color_from``: ``fixed`` fogs toward ``fog_color``;
    ``sky`` toward ``fog_color`` ⊙ the sky's horizon radiance in the pixel's azimuth (aerial
    perspective, :mod:`atmos.plugins.fog.sky_color`; give ``fog_color=(1, 1, 1)`` for the sky's own
    colour). Clouds that give their own distance (:mod:`atmos.composition`) are fogged by it. Every field is live: ``FogPlugin.configure`` changes
    it on the next frame (the pass fetches the program variant and noise volumes it needs).
    """

    mode: str = "exp2"
    density: float = 0.044
    fog_color: tuple = (0.8, 0.8, 0.8)
    start: float = 0.0
    end: float = 100.0
    sky: str = "fog"
    octaves: int = 4
    resolutions: tuple = PAPER_RESOLUTIONS["fine"]
    winds: tuple = DEFAULT_WINDS
    tile_size: float = 256.0
    amplitude: float = 1.0
    noise: str = "texture"
    texels_per_cell: int = 1
    seed: int = 0
    time_offset: float = 0.0
    color_from: str = "fixed"

    @property
    def heterogeneous(self) -> bool:
        return MODES[self.mode] >= 3

    @property
    def turns(self) -> tuple:
        """The octaves' turn angles about y (radians)."""
        return tuple(i * GOLDEN_ANGLE for i in range(4))

    def __post_init__(self):
        """Check every field (ValueError naming ``FogSettings.field``, the value and what is allowed);
        keeps the mode alias resolved and the tuples normalised."""
        o = _OWNER
        mode = ALIASES.get(self.mode, self.mode) if isinstance(self.mode, str) else self.mode
        if mode not in MODES:
            raise ValueError(f"{o}.mode must be one of {', '.join(MODES)} (aliases: {', '.join(ALIASES)}), "
                             f"got {self.mode!r}")
        start, end = check_num(o, "start", self.start), check_num(o, "end", self.end)
        if mode == "linear" and not start < end:
            raise ValueError(f"{o}.start must be < end for linear fog, got start={self.start!r}, end={self.end!r}")
        octaves = check_int(o, "octaves", self.octaves, 1, 4)
        tpc = check_int(o, "texels_per_cell", self.texels_per_cell, 1, MAX_TEXELS)
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
            mode=mode, start=start, end=end, octaves=octaves, texels_per_cell=tpc,
            density=check_num(o, "density", self.density, 0.0),
            fog_color=check_vec(o, "fog_color", self.fog_color, 3, "non-negative"),
            sky=check_choice(o, "sky", self.sky, SKIES),
            noise=check_choice(o, "noise", self.noise, NOISES),
            resolutions=tuple(check_int(o, f"resolutions[{i}]", r, 2, MAX_TEXELS // tpc)
                              for i, r in enumerate(resolutions)),
            winds=tuple(check_vec(o, f"winds[{i}]", w, 3) for i, w in enumerate(winds)),
            tile_size=check_num(o, "tile_size", self.tile_size, 0.0, lo_open=True),
            amplitude=check_num(o, "amplitude", self.amplitude, 0.0, 1.0),
            seed=check_int(o, "seed", self.seed, 0, 2**32 - 1),
            time_offset=check_num(o, "time_offset", self.time_offset),
            color_from=check_choice(o, "color_from", self.color_from, COLOR_SOURCES),
        ))
