"""FogSettings: every knob of the fog post-process, validated in one place (errors name what is allowed)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

MODES = {"linear": 0, "exp": 1, "exp2": 2, "hetero_exp": 3, "hetero_exp2": 4}
ALIASES = {"exponential": "exp", "exp_squared": "exp2", "squared_exponential": "exp2",
           "heterogeneous_exp": "hetero_exp", "heterogeneous_exp2": "hetero_exp2"}
NOISES = ("texture", "procedural")
SKIES = ("fog", "keep")
MAX_TEXELS = 256          # largest noise volume edge (resolution * texels_per_cell)
PAPER_RESOLUTIONS = {"fine": (16, 32, 64, 128), "coarse": (8, 16, 32, 64)}
DEFAULT_WINDS = ((1.5, 0.0, 0.5), (-1.0, 0.1, 1.2), (0.8, -0.05, -1.6), (-2.0, 0.0, -0.7))
GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))


@dataclass(frozen=True)
class FogSettings:
    """Fog factor mode (``linear``, ``exp``, ``exp2``, ``hetero_exp`` = eq. 6, ``hetero_exp2`` = eq. 7),
    density g, linear ``start``/``end``, ``fog_color`` (linear RGB) and sky handling (``fog``: sky
    pixels are fogged as at the far distance; ``keep``: left to the sky).

    Heterogeneous modes: ``octaves`` (1-4) of periodic gradient noise, octave i with ``resolutions[i]``
    lattice cells per ``tile_size`` metres, displaced by ``winds[i]`` m/s and turned about y by i golden
    angles; ``noise`` is ``texture`` (GPU-made tileable 3D textures of resolution * texels_per_cell
    texels, trilinear) or ``procedural`` (the same noise evaluated per pixel); ``amplitude`` in [0, 1]
    is the grey-scale range of an octave; ``seed`` picks the lattice gradients.
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

    @property
    def heterogeneous(self) -> bool:
        return MODES[self.mode] >= 3

    @property
    def turns(self) -> tuple:
        """The octaves' turn angles about y (radians)."""
        return tuple(i * GOLDEN_ANGLE for i in range(4))

    def validated(self) -> "FogSettings":
        """A copy with the mode alias resolved and tuples normalised; ValueError naming the allowed values."""
        mode = ALIASES.get(self.mode, self.mode) if isinstance(self.mode, str) else self.mode
        if mode not in MODES:
            raise ValueError(f"unknown fog mode {self.mode!r}; allowed: {', '.join(MODES)} "
                             f"(aliases: {', '.join(ALIASES)})")
        density = _number("density", self.density)
        if density < 0:
            raise ValueError(f"fog density must be >= 0 (a finite number), got {self.density!r}")
        start, end = _number("start", self.start), _number("end", self.end)
        if mode == "linear" and not start < end:
            raise ValueError(f"linear fog needs start < end, got start={self.start!r}, end={self.end!r}")
        color = _vector("fog_color", self.fog_color, 3)
        if self.sky not in SKIES:
            raise ValueError(f"sky must be one of {', '.join(SKIES)}, got {self.sky!r}")
        if self.noise not in NOISES:
            raise ValueError(f"noise must be one of {', '.join(NOISES)}, got {self.noise!r}")
        octaves = _integer("octaves", self.octaves, 1, 4)
        tpc = _integer("texels_per_cell", self.texels_per_cell, 1, MAX_TEXELS)
        try:
            resolutions = tuple(self.resolutions)
        except TypeError:
            raise ValueError(f"resolutions must be a sequence of 1-4 ints, got {self.resolutions!r}") from None
        if not octaves <= len(resolutions) <= 4:
            raise ValueError(f"resolutions needs {octaves} to 4 entries (one per octave), got {len(resolutions)}")
        resolutions = tuple(_integer("each resolution", r, 2, MAX_TEXELS // tpc) for r in resolutions)
        try:
            winds = tuple(self.winds)
        except TypeError:
            raise ValueError(f"winds must be 4 (x, y, z) velocities in m/s, got {self.winds!r}") from None
        if len(winds) != 4:
            raise ValueError(f"winds must be 4 (x, y, z) velocities in m/s (one per octave), got {len(winds)}")
        winds = tuple(_vector("each wind", w, 3) for w in winds)
        tile = _number("tile_size", self.tile_size)
        if not tile > 0:
            raise ValueError(f"tile_size must be > 0 metres, got {self.tile_size!r}")
        amplitude = _number("amplitude", self.amplitude)
        if not 0 <= amplitude <= 1:
            raise ValueError(f"amplitude must be in [0, 1], got {self.amplitude!r}")
        seed = _integer("seed", self.seed, 0, 2**32 - 1)
        return replace(self, mode=mode, density=density, fog_color=color, start=start, end=end,
                       octaves=octaves, resolutions=resolutions, winds=winds, tile_size=tile,
                       amplitude=amplitude, texels_per_cell=tpc, seed=seed)


def _number(name, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number, got {value!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return x


def _integer(name, value, low, high) -> int:
    if isinstance(value, bool) or not isinstance(value, int) and not (hasattr(value, "__index__")):
        raise ValueError(f"{name} must be an int in {low}..{high}, got {value!r}")
    value = int(value)
    if not low <= value <= high:
        raise ValueError(f"{name} must be an int in {low}..{high}, got {value}")
    return value


def _vector(name, value, n) -> tuple:
    try:
        items = tuple(value)
    except TypeError:
        raise ValueError(f"{name} must be {n} finite numbers, got {value!r}") from None
    if len(items) != n:
        raise ValueError(f"{name} must be {n} finite numbers, got {value!r}")
    return tuple(_number(name, v) for v in items)
