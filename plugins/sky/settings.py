"""SkySettings: every setting of the Preetham sky, checked as a whole before any of it is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import bool_field, check_shape, choice_field, int_field, nested_field, num_field, vec_field
from atmos.lighting import NIGHT_SKY
from atmos.sun_disc import SunDiscSettings
from atmos.plugins.sky.atmosphere_settings import AtmosphereSettings
from atmos.plugins.sky.preetham import TURBIDITY_RANGE, check_turbidity

_OWNER = "SkySettings"
MODELS = ("preetham", "physical")


@dataclass(frozen=True)
class SkySettings(SunDiscSettings):
    """Look of the sky: the sun disc (:class:`atmos.sun_disc.SunDiscSettings`' fields first), the model,
    haze, brightness in the HDR pipeline, night and stars (all live). The sun disc, night and stars are the same for both models. Two fields are checked
    by hand (not in the list below):

    ``turbidity`` = 2.5: the Preetham sky's haze, a number in [2, 10] (2 clear .. 10 hazy).
    ``aerial_froxels`` = (32, 32, 64): the aerial perspective's froxel volume (width, height, slices;
    each 1..256) that the pixels read trilinearly, each froxel column's ray marched slice by slice out
    to the far plane; None: every pixel marches its own ray in ``aerial_steps`` segments, as do rays
    beyond the volume (far clouds).
    """

    model: str = choice_field("preetham", MODELS, "preetham: the analytic sky (turbidity and scale set it, the "
                              "Sun's colour and ambient stay what DaylightPlugin or the game write); physical: "
                              "Hillaire 2020, a Rayleigh, Mie and ozone atmosphere (atmosphere), the sky plugin "
                              "then writing the Sun's colour and ambient from the same model every frame (see "
                              ":mod:`atmos.plugins.sky.sun_light`)")
    atmosphere: AtmosphereSettings = nested_field(AtmosphereSettings(), "the physical model's atmosphere")
    turbidity: float = 2.5
    scale: float = num_field(0.03, 0.0, 1e3, "HDR units per kcd/m² of Preetham luminance (0.03 puts a clear noon "
                             "zenith near 0.25, beside the sun colour ≈ 1 of sky_light)", lo_open=True)
    night: tuple = vec_field(tuple(map(float, NIGHT_SKY)), 3, "non-negative", "the sky colour once the sun is "
                             "well below the horizon")
    stars: bool = bool_field(True, "draw the stars")
    star_density: float = num_field(0.08, 0.0, 1.0, "fraction of star-grid cells holding a star")
    star_brightness: float = num_field(4.0, 0.0, 1e4, "HDR radiance of the brightest star")
    twinkle: float = num_field(0.4, 0.0, 1.0, "0 steady .. 1 full")
    aerial_perspective: bool = bool_field(False, "the physical model only: the air between the camera and the "
                                          "scene hazes it with the sky's own light "
                                          "(:mod:`atmos.plugins.sky.aerial`; aerial_froxels)")
    aerial_steps: int = int_field(8, 1, 256, "segments of a pixel's own aerial ray (8: within 8e-4 of a 96-step "
                                  "float64 march from 10 km up, 6e-4 near the ground; benchmarks/bench_sky.py)")
    aerial_froxels: tuple | None = (32, 32, 64)

    def __post_init__(self):
        super().__post_init__()
        o = _OWNER
        try:
            turbidity = check_turbidity(self.turbidity)
        except ValueError:
            raise ValueError(f"{o}.turbidity must be a number in {list(TURBIDITY_RANGE)} "
                             f"(2 clear .. 10 hazy), got {self.turbidity!r}") from None
        self.store(dict(turbidity=turbidity,
                        aerial_froxels=check_shape(self.aerial_froxels, f"{o}.aerial_froxels", hi=256,
                                                   optional=True)))
