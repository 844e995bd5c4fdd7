"""LightShaftSettings: the settings of the light shafts, checked as a whole before any is used (all live)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, check_shape, choice_field, int_field, nested_field, num_field
from atmos.froxels import MAX_FROXELS, history_field
from atmos.phase import Phase

MODES = ("march", "screen")
MAX_SAMPLES = 256
MAX_STEPS = 256
MAX_DOWNSAMPLE = 8
FLOAT32_MAX = float(np.finfo(np.float32).max)   # a float32 uniform of more is inf


@dataclass(frozen=True)
class LightShaftSettings(CheckedSettings):
    """Light shafts marched through the cloud shadow map (``mode="march"``, the default) or an
    occlusion mask blurred radially toward the sun (``mode="screen"``, GPU Gems 3, ch. 13).

    March (:mod:`atmos.plugins.light_shafts.march`): along each pixel's view ray to the scene depth,
    jittered samples gather sun light scattered by a thin haze, the sun reaching each sample through
    the clouds (the ground shadows' column sums, :mod:`atmos.plugins.clouds.shadows`) and the haze's
    own transmittance toward the eye dimming the colour behind; at 1/``downsample`` resolution,
    upsampled by depth. With a FogPlugin the fog owns the air's in-scattering: the shafts take away
    the sunlit share of the fog's in-scatter where the clouds shadow the air (so the haze is counted
    once); without a fog but with the physical sky's aerial perspective, likewise its single-scattered
    sunlight (``phase`` and ``scattering`` then unused).

    ``froxels`` = (W, H, D), each 1..256 (default 160 × 90 × 64): the march runs through a froxel volume
    (:mod:`atmos.plugins.light_shafts.froxels`) — each of W × H view-ray columns marched once in D slices
    (even near the camera, logarithmic beyond max_distance / 32), every pixel reading it at its own
    distance (``steps`` and ``downsample`` then unused): W·H·D samples whatever the frame's size, edges
    as soft as a column; each slice's sample moves every frame and the frames are averaged through
    reprojection (``froxel_history``), so a still view converges to the slices' mean, without bands.
    None (or a heterogeneous fog): per texel at 1/``downsample`` resolution, ``steps`` jittered samples
    each (``benchmarks/bench_light_shafts.py`` compares both).

    Screen: sky pixels brighter than ``threshold`` near the sun (open to the sky: ``1 − color.a``)
    form a mask, blurred toward the sun's screen position and added to the colour (at most
    :data:`atmos.render_core.HDR_MAX`); clouds drawn over the sky cut the shafts.
    """

    mode: str = choice_field("march", MODES, "march: rays through the cloud shadows; screen: a radial blur")
    steps: int = int_field(24, 1, MAX_STEPS, "march: samples per ray")
    scattering: float = num_field(6e-6, 0.0, 1.0, "march: the haze's scattering coefficient (1/m, albedo 1); "
                                  "tuned at the sunset (sun 4.6°): rays visible, no wash round the sun")
    max_distance: float = num_field(8000.0, 0.0, 1e7, "march: m marched where the ray sees sky", lo_open=True)
    phase: Phase = nested_field(Phase(0.5, -0.2, 0.2), "march: the haze's two-lobe phase function")
    sun_intensity: float = num_field(4.0 * math.pi, 0.0, doc="march: sun irradiance = this × Sun.color")
    samples: int = int_field(48, 1, MAX_SAMPLES, "screen: blur taps on the way to the sun")
    density: float = num_field(0.9, 0.0, 1.0, "screen: the share of the way to the sun the taps cover", lo_open=True)
    decay: float = num_field(0.96, 0.0, 1.0, "screen: tap i (1-based) weighs weight · decay^(i−1)", lo_open=True)
    weight: float = num_field(0.06, 0.0, doc="screen: the first tap's weight")
    exposure: float = num_field(0.5, 0.0, doc="screen: the blur's sum is scaled by this")
    threshold: float = num_field(0.6, 0.0, doc="screen: sky luminance (linear HDR) above which a pixel casts")
    ceiling: float = num_field(1.0, 0.0, doc="screen: the most a pixel casts (the sun disc no brighter than "
                               "the sky round it)", lo_open=True)
    radius: float = num_field(0.4, 0.0, doc="screen: the mask falls off as exp(−(r/radius)²), r from the sun "
                              "in screen heights", lo_open=True)
    downsample: int = int_field(2, 1, MAX_DOWNSAMPLE, "the shafts' resolution is the frame's / this (a change "
                                "resizes them on the next frame)")
    horizon_fade: float = num_field(0.1, 0.0, 1.0, "fades the shafts out as the sun's height (y of its unit "
                                    "direction) falls from this to 0", lo_open=True)
    front_fade: float = num_field(0.3, 0.0, 1.0, "screen: fades them out as the cosine between the view and the "
                                  "sun falls from this to 0", lo_open=True)
    edge_fade: float = num_field(0.5, 0.0, doc="screen: fades them out as the sun leaves the screen, over this "
                                 "many screen widths", lo_open=True)
    fog_sun_share: float = num_field(0.8, 0.0, 1.0, "with a fog: the part of the fog's colour that is sunlight "
                                     "(what cloud shadow takes away)")
    froxels: tuple | None = (160, 90, 64)
    froxel_history: float = history_field()

    def __post_init__(self):
        super().__post_init__()
        self.store(dict(froxels=check_shape(self.froxels, "LightShaftSettings.froxels", hi=MAX_FROXELS,
                                            optional=True)))


def blur_scale(settings: LightShaftSettings, strength: float) -> float:
    """``weight × exposure × strength``, the screen mode's blur scale, at most float32's largest
    finite value (a float32 uniform of more is inf, and inf × a dark tap NaN)."""
    return min(settings.weight * settings.exposure * strength, FLOAT32_MAX)
