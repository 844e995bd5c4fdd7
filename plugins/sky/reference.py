"""The whole sky colour in float64 numpy, as ``shaders/sky/sky.glsl`` draws it.

``sky_radiance`` (the diffuse sky, for anyone who wants the sky's light in a direction):
``mix(night, scale · preetham, day) · below``, where ``day`` fades the Preetham sky out over twilight
(the sun's height, sin elevation, from ``DAY_FADE[1]`` down to ``DAY_FADE[0]``) and ``below`` dims
views under the horizon toward ``GROUND_DIM`` over view heights 0..-``BELOW_FADE``.
``sky_color`` adds the sun disc (``sun_gain`` × the Sun resource's colour inside ``sun_size_deg``,
soft over the outer ``DISC_EDGE`` of its radius, measured as the chord |v − s| so the GPU needs no
inverse trigonometry there) and the stars of :mod:`atmos.plugins.sky.stars`.
"""
from __future__ import annotations

import math

import numpy as np

from atmos.lighting import NIGHT_SKY
from atmos.plugins.sky.settings import SkySettings
from atmos.plugins.sky.preetham import check_turbidity, preetham_rgb, unit_vectors
from atmos.plugins.sky.stars import smoothstep, star_field
# the model's constants are the GLSL's (handed over as defines by .shader); kept here by name
from atmos.plugins.sky.shader import BELOW_FADE, DAY_FADE, DISC_EDGE, GROUND_DIM, disc_chords  # noqa: F401


def daylight(sun_y) -> np.ndarray:
    """0 (night) .. 1 (day): how much of the Preetham sky is shown for a sun at height ``sun_y``."""
    return smoothstep(*DAY_FADE, sun_y)


def below_horizon(view_y) -> np.ndarray:
    """1 above the horizon, down to GROUND_DIM under it."""
    return 1.0 + (GROUND_DIM - 1.0) * smoothstep(0.0, -BELOW_FADE, view_y)


def sky_radiance(view_dir, sun_dir, turbidity: float = SkySettings.turbidity, scale: float = SkySettings.scale,
                 night=tuple(NIGHT_SKY)) -> np.ndarray:
    """(..., 3) linear HDR sky colour (no sun disc, no stars) for view directions ``view_dir`` (..., 3)
    and the direction toward the sun ``sun_dir`` (3,); any direction, sun above or below the horizon."""
    check_turbidity(turbidity)
    v = unit_vectors(view_dir, "view_dir")
    s = unit_vectors(sun_dir, "sun_dir").reshape(3)
    day = daylight(s[1])
    rgb = np.asarray(night, np.float64) * (1.0 - day) + scale * preetham_rgb(v, s, turbidity) * day
    return rgb * below_horizon(v[..., 1])[..., None]


def sun_disc(view_dir, sun_dir, sun_color, size_deg: float, gain: float) -> np.ndarray:
    """(..., 3) the sun disc's radiance: ``gain · sun_color`` inside, soft edge (unit directions)."""
    inside = 1.0 - smoothstep(*disc_chords(size_deg), np.linalg.norm(view_dir - sun_dir, axis=-1))
    return gain * inside[..., None] * np.asarray(sun_color, np.float64)


def sky_color(view_dir, sun_dir, sun_color, settings: SkySettings | None = None, time: float = 0.0,
              pixel_angle: float = 0.0) -> np.ndarray:
    """(..., 3) what the sky pass writes: sky radiance, sun disc and (if ``settings.stars``) stars."""
    p = settings or SkySettings()
    v = unit_vectors(view_dir, "view_dir")
    s = unit_vectors(sun_dir, "sun_dir").reshape(3)
    extra = sun_disc(v, s, sun_color, p.sun_size_deg, p.sun_gain)
    if p.stars:
        extra = extra + star_field(v, s[1], time, pixel_angle, p.star_density, p.star_brightness, p.twinkle)
    return sky_radiance(v, s, p.turbidity, p.scale, p.night) + extra * below_horizon(v[..., 1])[..., None]
