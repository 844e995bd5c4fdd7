"""PhysicalCameraSettings: exposure in EV100, metered and adapted over time or set by hand, and bloom."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, bool_field, int_field, num_field, vec_field

MAX_BLOOM_LEVELS = 8


@dataclass(frozen=True)
class PhysicalCameraSettings(CheckedSettings):
    """How the camera exposes the HDR frame and how much it glows (all live: a change shows on the next
    frame). EV100 is of the scene's radiance taken as luminance (cd/m² for a sun in physical units);
    a camera at EV100 scales the frame by 1 / (1.2 · 2^EV100), which brings a metered average to 1/9.6.

    Checked by hand after the rules listed below: ``ev_range`` must rise and ``metering_filter`` must be
    (low, high) with 0 <= low < high <= 1."""
    auto_exposure: bool = bool_field(True, "meter every frame (a luminance histogram on the GPU, read there: "
                                     "no wait) and adapt the EV100 toward it over time; False: ``ev100``")
    ev100: float = num_field(0.0, -20.0, 30.0, "EV100 by hand while ``auto_exposure`` is off (0: the frame "
                             "× 0.83; each +1 halves it)")
    compensation: float = num_field(1.0, -10.0, 10.0, "EV added to the metered exposure (+1: an image twice "
                                    "as bright; the default +1 puts a metered average at 0.21 before the tone "
                                    "map, a mid grey on screen, where 0 gives a dim 40 % grey)")
    ev_range: tuple = vec_field((-6.0, 14.0), 2, doc="(lowest, highest) EV100 the histogram spans and the "
                                "adaptation stays within (a night sky below the lowest is shown as at it)")
    metering_filter: tuple = vec_field((0.1, 0.9), 2, doc="(low, high): the mean leaves out the darkest "
                                       "``low`` and the brightest 1 - ``high`` of the pixels (the sun's disc, "
                                       "deep shadow)")
    speed_up: float = num_field(3.0, 0.0, 100.0, "EV per second the camera follows a brighter scene (an eye "
                                "closing: fast)", lo_open=True)
    speed_down: float = num_field(1.0, 0.0, 100.0, "EV per second it follows a darker one (slow)", lo_open=True)
    transition: float = num_field(1.5, 0.01, 20.0, "EV from the target below which the change slows "
                                  "exponentially (no jolt at the end)")
    bloom: float = num_field(0.04, 0.0, 1.0, "share of the frame replaced by its blurred copy (the lens's glow "
                             "around the sun and bright clouds; energy kept; 0: no bloom passes)")
    bloom_levels: int = int_field(5, 1, MAX_BLOOM_LEVELS, "halvings of the blur chain, from half size, level k "
                                  "weighing 2^-k (5: a halo fading out some 200 px from a bright source; each "
                                  "level costs a quarter of the last and two dispatches)")
    enabled: bool = bool_field(True, "False: no passes; the present uses ``RenderCoreSettings.exposure``")

    def __post_init__(self):
        super().__post_init__()
        lo, hi = self.ev_range
        if not lo < hi:
            raise ValueError(f"PhysicalCameraSettings.ev_range must rise (lowest < highest EV100), got {self.ev_range!r}")
        low, high = self.metering_filter
        if not 0.0 <= low < high <= 1.0:
            raise ValueError(f"PhysicalCameraSettings.metering_filter must be (low, high) with 0 <= low < high <= 1 "
                             f"(shares of the pixels), got {self.metering_filter!r}")
