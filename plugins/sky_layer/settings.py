"""SkyLayerSettings: every setting of the 2D cloud layer, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, bool_field, check_vec, int_field, num_field, vec_field

_OWNER = "SkyLayerSettings"
MIN_GAP = 1e-3          # sharpness − emptiness must be at least this (the remap divides by it)
# scroll of octaves 0..3 in tiles per second: speeds 1, 1.5, 2, 2.5 along +x, +z, −z, −x (the article's)
DEFAULT_WIND = ((0.002, 0.0), (0.0, 0.003), (0.0, -0.004), (-0.005, 0.0))
TEXTURE_SETTINGS = ("size", "base_frequency", "seed", "light_step")   # changing one re-bakes the octaves


@dataclass(frozen=True)
class SkyLayerSettings(CheckedSettings):
    """Look (emptiness, sharpness, thickness, colours), placement (altitude, tile_size) and motion (wind)
    of the 2D cloud layer (all live; changing size, base_frequency, seed or light_step re-bakes the
    octave textures). Octave k has ``base_frequency · 2^k`` noise cells across one tile of
    ``tile_size`` metres. ``wind`` is checked by hand (not in the list below):

    ``wind`` = DEFAULT_WIND: 4 × (x, z) tiles per second, octave 0 (lowest frequency) first.
    """

    emptiness: float = num_field(0.4, 0.0, 1.0, "fbm at or below this is clear sky")
    sharpness: float = num_field(0.6, 0.0, 1.0, f"fbm at or above this is full cloud; at least emptiness + {MIN_GAP}")
    thickness: float = num_field(1.5, 0.0, doc="opacity per unit of light-march amount")
    color: tuple = vec_field((0.42, 0.45, 0.52), 3, "non-negative", "shadowed (thick) cloud colour")
    lit_color: tuple = vec_field((0.85, 0.85, 0.85), 3, "non-negative", "sunlit (thin) cloud colour")
    altitude: float = num_field(1500.0, doc="metres: the layer is the plane y = this")
    tile_size: float = num_field(4000.0, 0.0, doc="metres one texture repeat covers", lo_open=True)
    horizon_fade: float = num_field(0.12, 0.0, 1.0, "the layer fades in over view-ray heights 0..this",
                                    lo_open=True)
    wind: tuple = DEFAULT_WIND
    size: int = int_field(256, 16, 2048, "octave texture resolution (texels per side)")
    base_frequency: int = int_field(4, 1, 64, "noise cells across a tile at octave 0")
    seed: int = int_field(0, 0, 2**32 - 1, "the noise's seed")
    light_step: float = num_field(0.01, 0.0, 0.25, "tiles between the four light-march samples toward the sun")
    rebake_tolerance: float = num_field(0.05, 0.0, 1.0, "re-bake when the sun moved the light step by this "
                                        "fraction")
    animate: bool = bool_field(True, "scroll with the App clock (False: frozen at time 0)")

    def __post_init__(self):
        given = self.emptiness, self.sharpness          # as given, for the message
        super().__post_init__()
        o = _OWNER
        try:
            wind = tuple(check_vec(o, f"wind[{k}]", w, 2) for k, w in enumerate(self.wind))
        except TypeError:
            wind = ()
        if len(wind) != 4:
            raise ValueError(f"{o}.wind must be 4 (x, z) pairs in tiles per second, got {self.wind!r}")
        if self.sharpness - self.emptiness < MIN_GAP:
            raise ValueError(f"{o}.sharpness must exceed emptiness by at least {MIN_GAP} "
                             f"(got emptiness={given[0]!r}, sharpness={given[1]!r})")
        self.store(dict(wind=wind))

    def texture_key(self) -> tuple:
        """The settings the baked octave textures depend on."""
        return tuple(getattr(self, name) for name in TEXTURE_SETTINGS)
