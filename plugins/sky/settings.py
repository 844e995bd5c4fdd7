"""SkySettings: every setting of the Preetham sky, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_bool, check_choice, check_int, check_num, check_shape, check_vec
from atmos.lighting import NIGHT_SKY
from atmos.plugins.sky.atmosphere_settings import AtmosphereSettings
from atmos.plugins.sky.preetham import TURBIDITY_RANGE, check_turbidity

_OWNER = "SkySettings"
MODELS = ("preetham", "physical")


@dataclass(frozen=True)
class SkySettings(CheckedSettings):
    """Look of the sky: the model, haze, brightness in the HDR pipeline, sun disc, night and stars.

    ``model``: ``"preetham"`` (the analytic sky; ``turbidity`` and ``scale`` set it, the Sun's colour
    and ambient stay what DaylightPlugin or the game write) or ``"physical"`` (Hillaire 2020: a
    Rayleigh, Mie and ozone atmosphere, ``atmosphere`` an :class:`AtmosphereSettings`; the sky plugin
    then writes the Sun's colour and ambient from the same model every frame, see
    :mod:`atmos.plugins.sky.sun_light`). The sun disc, night and stars are the same for both.
    ``scale``: HDR units per kcd/m² of Preetham luminance (0.03 puts a clear noon zenith near 0.25,
    beside the sun colour ≈ 1 of ``sky_light``); ``sun_size_deg``: angular radius of the disc
    (the real sun's: 0.2665°, 0.53° across); ``sun_gain``: radiance at the disc's centre per unit of
    the Sun resource's colour (limb-darkened toward the edge); ``sun_glare``: the glare round the
    disc, as a fraction of the centre's radiance at the disc's edge (falling as 1/angle² beyond it); ``night``: the sky colour
    once the sun is well below the horizon; ``star_density``: fraction of star-grid cells holding
    a star; ``star_brightness``: HDR radiance of the brightest star; ``twinkle``: 0 steady .. 1 full.
    ``aerial_perspective`` (the physical model only): the air between the camera and the scene hazes it
    with the sky's own light (:mod:`atmos.plugins.sky.aerial`), from a froxel volume of ``aerial_froxels``
    (width, height, slices; each 1..256) that the pixels read trilinearly, each froxel column's ray
    marched slice by slice out to the far plane; None: every pixel marches its own ray in
    ``aerial_steps`` segments (8: within 8e-4 of a 96-step float64 march from 10 km up, 6e-4 near the
    ground; benchmarks/bench_sky.py), as do rays beyond the volume (far clouds).
    """

    model: str = "preetham"
    atmosphere: AtmosphereSettings = AtmosphereSettings()
    turbidity: float = 2.5
    scale: float = 0.03
    sun_size_deg: float = 0.2665
    sun_gain: float = 20.0
    sun_glare: float = 0.05
    night: tuple = tuple(NIGHT_SKY)
    stars: bool = True
    star_density: float = 0.08
    star_brightness: float = 4.0
    twinkle: float = 0.4
    aerial_perspective: bool = False
    aerial_steps: int = 8
    aerial_froxels: tuple | None = (32, 32, 64)

    def __post_init__(self):
        o = _OWNER
        if not isinstance(self.atmosphere, AtmosphereSettings):
            raise ValueError(f"{o}.atmosphere must be an AtmosphereSettings, got {type(self.atmosphere).__name__}")
        try:
            turbidity = check_turbidity(self.turbidity)
        except ValueError:
            raise ValueError(f"{o}.turbidity must be a number in {list(TURBIDITY_RANGE)} "
                             f"(2 clear .. 10 hazy), got {self.turbidity!r}") from None
        checked = dict(
            model=check_choice(o, "model", self.model, MODELS),
            turbidity=turbidity,
            stars=check_bool(o, "stars", self.stars),
            scale=check_num(o, "scale", self.scale, 0.0, 1e3, lo_open=True),
            sun_size_deg=check_num(o, "sun_size_deg", self.sun_size_deg, 0.0, 5.0, lo_open=True),
            sun_gain=check_num(o, "sun_gain", self.sun_gain, 0.0, 1e4),
            sun_glare=check_num(o, "sun_glare", self.sun_glare, 0.0, 1.0),
            night=check_vec(o, "night", self.night, 3, "non-negative"),
            star_density=check_num(o, "star_density", self.star_density, 0.0, 1.0),
            star_brightness=check_num(o, "star_brightness", self.star_brightness, 0.0, 1e4),
            twinkle=check_num(o, "twinkle", self.twinkle, 0.0, 1.0),
            aerial_perspective=check_bool(o, "aerial_perspective", self.aerial_perspective),
            aerial_steps=check_int(o, "aerial_steps", self.aerial_steps, 1, 256),
            aerial_froxels=check_shape(self.aerial_froxels, f"{o}.aerial_froxels", hi=256, optional=True),
        )
        self.store(checked)
