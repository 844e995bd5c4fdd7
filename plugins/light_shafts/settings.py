"""LightShaftSettings: the settings of the light shafts, checked as a whole before any is used (all live)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, check_choice, check_int, check_num

MODES = ("march", "screen")
MAX_SAMPLES = 256
MAX_STEPS = 256
MAX_DOWNSAMPLE = 8
FLOAT32_MAX = float(np.finfo(np.float32).max)   # a float32 uniform of more is inf
_OWNER = "LightShaftSettings"


@dataclass(frozen=True)
class LightShaftSettings(CheckedSettings):
    """Light shafts marched through the cloud shadow map (``mode="march"``, the default) or an
    occlusion mask blurred radially toward the sun (``mode="screen"``, GPU Gems 3, ch. 13), and when
    the effect shows.

    March (:mod:`atmos.plugins.light_shafts.march`): along each pixel's view ray to the scene depth
    (the sky: ``max_distance`` metres), ``steps`` samples from a per-pixel jittered start gather sun
    light scattered by a thin haze of scattering coefficient ``scattering`` (1/m, albedo 1) with the
    two-lobe Henyey-Greenstein phase ``phase_g``, ``phase_g2``, ``phase_w`` of
    :mod:`atmos.plugins.clouds.light.medium`, the sun irradiance ``sun_intensity × Sun.color`` reaching each
    sample through the clouds (the ground shadows' density maps, :mod:`atmos.plugins.clouds.shadows`;
    no clouds: unshadowed haze) and the haze's own transmittance toward the eye, which also dims the
    colour behind. At 1/``downsample`` resolution, upsampled by depth. Shafts are real rays: the air
    between cloud shadows is lit, the air in them is not. With a FogPlugin in the App the fog owns the
    air's in-scattering (its colour already holds it): the shafts then add no light and no extinction
    of their own but take away the share ``fog_sun_share`` (the part of the fog's colour that is
    sunlight; the rest is sky light, which cloud shadow leaves) of the fog's in-scatter along each ray
    where the clouds shadow the air, so the haze is counted once (``shaders/light_shafts/march.frag``).
    Without a fog but with the physical sky's aerial perspective (``SkySettings.aerial_perspective``)
    the atmosphere owns it: the shafts take away its single-scattered sunlight where the clouds shadow
    the air (the same atmosphere and LUTs; ``phase_*`` and ``scattering`` are then unused). ``horizon_fade`` fades it with the sun's
    height; ``samples`` … ``ceiling``, ``radius``, ``front_fade``, ``edge_fade`` are the screen mode's.

    Screen:
    Mask: sky pixels (depth 1) whose luminance exceeds ``threshold`` (linear HDR) keep the excess,
    at most ``ceiling`` (so the sun disc does not outshine the sky around it), in their own colour,
    times how open to the sky they are, ``1 − color.a``, times ``exp(−(r/radius)²)``, r the distance
    from the sun's screen position in screen heights: only the open sky near the sun casts shafts
    (thesis 7.3.2). ``color.a`` is the sky occlusion every pass keeps (:mod:`atmos.render_core`):
    0 on open sky, 1 on opaque geometry or cloud, the coverage on cloud edges. So clouds drawn over
    the sky cut the shafts however brightly the sun lights them; fog tints the sky but keeps it sky.
    Blur, per pixel: ``samples`` taps on the way to the sun covering ``density`` of it; tap i
    (1-based) weighs ``weight · decay^(i−1)``; the sum times ``exposure``, at most
    :data:`atmos.render_core.HDR_MAX`, is added to the colour.
    ``downsample``: mask and blur at 1/downsample of the frame size (read by the pass's ``setup``
    every frame: a change resizes them on the next frame).
    Fades (1 → 0): ``horizon_fade``: the sun's height (y of its unit direction) from this down to 0;
    ``front_fade``: the cosine between the view direction and the sun from this down to 0 (behind
    the camera: none); ``edge_fade``: the sun's screen position from the screen edge to this far
    outside it (in screen widths/heights).
    """

    mode: str = "march"
    steps: int = 24
    scattering: float = 6e-6          # tuned at the sunset (sun 4.6°): rays visible, no wash round the sun
    max_distance: float = 8000.0
    phase_g: float = 0.5
    phase_g2: float = -0.2
    phase_w: float = 0.2
    sun_intensity: float = 4.0 * math.pi
    samples: int = 48
    density: float = 0.9
    decay: float = 0.96
    weight: float = 0.06
    exposure: float = 0.5
    threshold: float = 0.6
    ceiling: float = 1.0
    radius: float = 0.4
    downsample: int = 2
    horizon_fade: float = 0.1
    front_fade: float = 0.3
    edge_fade: float = 0.5
    fog_sun_share: float = 0.8

    def __post_init__(self):
        o = _OWNER
        checked = dict(
            mode=check_choice(o, "mode", self.mode, MODES),
            steps=check_int(o, "steps", self.steps, 1, MAX_STEPS),
            scattering=check_num(o, "scattering", self.scattering, 0.0, 1.0),
            max_distance=check_num(o, "max_distance", self.max_distance, 0.0, 1e7, lo_open=True),
            phase_g=check_num(o, "phase_g", self.phase_g, -0.99, 0.99),
            phase_g2=check_num(o, "phase_g2", self.phase_g2, -0.99, 0.99),
            phase_w=check_num(o, "phase_w", self.phase_w, 0.0, 1.0),
            sun_intensity=check_num(o, "sun_intensity", self.sun_intensity, 0.0),
            samples=check_int(o, "samples", self.samples, 1, MAX_SAMPLES),
            density=check_num(o, "density", self.density, 0.0, 1.0, lo_open=True),
            decay=check_num(o, "decay", self.decay, 0.0, 1.0, lo_open=True),
            weight=check_num(o, "weight", self.weight, 0.0),
            exposure=check_num(o, "exposure", self.exposure, 0.0),
            threshold=check_num(o, "threshold", self.threshold, 0.0),
            ceiling=check_num(o, "ceiling", self.ceiling, 0.0, lo_open=True),
            radius=check_num(o, "radius", self.radius, 0.0, lo_open=True),
            downsample=check_int(o, "downsample", self.downsample, 1, MAX_DOWNSAMPLE),
            horizon_fade=check_num(o, "horizon_fade", self.horizon_fade, 0.0, 1.0, lo_open=True),
            front_fade=check_num(o, "front_fade", self.front_fade, 0.0, 1.0, lo_open=True),
            edge_fade=check_num(o, "edge_fade", self.edge_fade, 0.0, lo_open=True),
            fog_sun_share=check_num(o, "fog_sun_share", self.fog_sun_share, 0.0, 1.0),
        )
        self.store(checked)


def blur_scale(settings: LightShaftSettings, strength: float) -> float:
    """``weight × exposure × strength``, the screen mode's blur scale, at most float32's largest
    finite value (a float32 uniform of more is inf, and inf × a dark tap NaN)."""
    return min(settings.weight * settings.exposure * strength, FLOAT32_MAX)
