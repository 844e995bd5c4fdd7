"""SkyLayerSettings: every setting of the 2D cloud layer, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_bool, check_int, check_num, check_vec

_OWNER = "SkyLayerSettings"
MIN_GAP = 1e-3          # sharpness − emptiness must be at least this (the remap divides by it)
# scroll of octaves 0..3 in tiles per second: speeds 1, 1.5, 2, 2.5 along +x, +z, −z, −x (the article's)
DEFAULT_WIND = ((0.002, 0.0), (0.0, 0.003), (0.0, -0.004), (-0.005, 0.0))
TEXTURE_SETTINGS = ("size", "base_frequency", "seed", "light_step")   # changing one re-bakes the octaves


@dataclass(frozen=True)
class SkyLayerSettings(CheckedSettings):
    """Look (emptiness, sharpness, thickness, colours), placement (altitude, tile_size) and motion (wind).

    Octave k has ``base_frequency · 2^k`` noise cells across one tile of ``tile_size`` metres.
    """

    emptiness: float = 0.4            # fbm at or below this is clear sky
    sharpness: float = 0.6            # fbm at or above this is full cloud
    thickness: float = 1.5            # opacity per unit of light-march amount
    color: tuple = (0.42, 0.45, 0.52)       # shadowed (thick) cloud colour
    lit_color: tuple = (0.85, 0.85, 0.85)   # sunlit (thin) cloud colour
    altitude: float = 1500.0          # metres
    tile_size: float = 4000.0         # metres one texture repeat covers
    horizon_fade: float = 0.12        # the layer fades in over view-ray heights 0..horizon_fade
    wind: tuple = DEFAULT_WIND        # 4 × (x, z) tiles per second, octave 0 (lowest frequency) first
    size: int = 256                   # octave texture resolution (texels per side), 16..2048
    base_frequency: int = 4           # noise cells across a tile at octave 0, 1..64
    seed: int = 0
    light_step: float = 0.01          # tiles between the four light-march samples toward the sun
    rebake_tolerance: float = 0.05    # re-bake when the sun moved the light step by this fraction, 0..1
    animate: bool = True              # scroll with the App clock (False: frozen at time 0)

    def __post_init__(self):
        o = _OWNER
        try:
            wind = tuple(check_vec(o, f"wind[{k}]", w, 2) for k, w in enumerate(self.wind))
        except TypeError:
            wind = ()
        if len(wind) != 4:
            raise ValueError(f"{o}.wind must be 4 (x, z) pairs in tiles per second, got {self.wind!r}")
        checked = dict(
            emptiness=check_num(o, "emptiness", self.emptiness, 0.0, 1.0),
            sharpness=check_num(o, "sharpness", self.sharpness, 0.0, 1.0),
            thickness=check_num(o, "thickness", self.thickness, 0.0),
            color=check_vec(o, "color", self.color, 3, "non-negative"),
            lit_color=check_vec(o, "lit_color", self.lit_color, 3, "non-negative"),
            altitude=check_num(o, "altitude", self.altitude),
            tile_size=check_num(o, "tile_size", self.tile_size, 0.0, lo_open=True),
            horizon_fade=check_num(o, "horizon_fade", self.horizon_fade, 0.0, 1.0, lo_open=True),
            wind=wind,
            size=check_int(o, "size", self.size, 16, 2048),
            base_frequency=check_int(o, "base_frequency", self.base_frequency, 1, 64),
            seed=check_int(o, "seed", self.seed, 0, 2**32 - 1),
            light_step=check_num(o, "light_step", self.light_step, 0.0, 0.25),
            rebake_tolerance=check_num(o, "rebake_tolerance", self.rebake_tolerance, 0.0, 1.0),
            animate=check_bool(o, "animate", self.animate),
        )
        if checked["sharpness"] - checked["emptiness"] < MIN_GAP:
            raise ValueError(f"{o}.sharpness must exceed emptiness by at least {MIN_GAP} "
                             f"(got emptiness={self.emptiness!r}, sharpness={self.sharpness!r})")
        self.store(checked)

    def texture_key(self) -> tuple:
        """The settings the baked octave textures depend on."""
        return tuple(getattr(self, name) for name in TEXTURE_SETTINGS)
