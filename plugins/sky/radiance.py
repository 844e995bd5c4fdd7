"""The whole sky colour in float64 numpy, as ``shaders/sky/sky.glsl`` draws it: what effects ask of the
sky's light at run time (the Sun's daylight, the fog's horizon) and what the sky's tests compare with.

``sky_radiance`` (the diffuse sky, for anyone who wants the sky's light in a direction):
``mix(night, scale · preetham · ozone, day) · below``, where ``ozone`` is the Chappuis absorption
Preetham leaves out (:func:`ozone_transmittance`: what keeps the twilight zenith blue, not grey;
raised to ``max(view_y, 0)²``: full overhead, where the twilight sky is lit from high up, fading
toward the horizon glow, lit through the lower air), ``day`` fades the Preetham sky out over twilight
(the sun's height, sin elevation, from ``DAY_FADE[1]`` down to ``DAY_FADE[0]``) and ``below`` dims
views under the horizon toward ``GROUND_DIM`` over view heights 0..-``BELOW_FADE``.
``sky_color`` adds the sun disc and its glare (:func:`sun_disc`, measured as the chord |v − s| so
the GPU needs no inverse trigonometry there) and the stars of :mod:`atmos.plugins.sky.stars`
(:func:`extras`, shared with the physical sky: :func:`physical_sky_color`).
"""
from __future__ import annotations

import math

import numpy as np

from atmos.lighting import NIGHT_SKY
from atmos.plugins.sky.settings import SkySettings
from atmos.plugins.sky.preetham import check_turbidity, preetham_rgb, unit_vectors
from atmos.plugins.sky.stars import smoothstep, star_field
# the model's constants are the GLSL's (handed over as defines by .shader); kept here by name
from atmos.plugins.sky.shader import (BELOW_FADE, DAY_FADE, GROUND_DIM, OZONE_BELOW, OZONE_DEPTH,  # noqa: F401
                                      OZONE_SHELL)
from atmos.sun_disc import sun_disc


def ozone_transmittance(sun_y) -> np.ndarray:
    """(3,) RGB transmittance of the sky's light through the ozone layer relative to a sun at the
    zenith: ``exp(−OZONE_DEPTH · (m − m_zenith))`` with the slant path through a thin shell,
    ``m = 1 / sqrt(max(sun_y, 0)² + OZONE_SHELL)``, lengthened by ``1 + OZONE_BELOW · depth`` for a
    sun below the horizon (its light then crosses the layer twice, tangentially)."""
    y = float(sun_y)
    m = (1.0 + OZONE_BELOW * max(-y, 0.0)) / math.sqrt(max(y, 0.0) ** 2 + OZONE_SHELL)
    return np.exp(-np.array(OZONE_DEPTH) * (m - 1.0 / math.sqrt(1.0 + OZONE_SHELL)))


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
    ozone = ozone_transmittance(s[1]) ** (np.maximum(v[..., 1:2], 0.0) ** 2)
    rgb = np.asarray(night, np.float64) * (1.0 - day) + scale * preetham_rgb(v, s, turbidity) * ozone * day
    return rgb * below_horizon(v[..., 1])[..., None]


def sky_color(view_dir, sun_dir, sun_color, settings: SkySettings | None = None, time: float = 0.0,
              pixel_angle: float = 0.0) -> np.ndarray:
    """(..., 3) what the sky pass writes: sky radiance, sun disc and (if ``settings.stars``) stars."""
    p = settings or SkySettings()
    v = unit_vectors(view_dir, "view_dir")
    s = unit_vectors(sun_dir, "sun_dir").reshape(3)
    return sky_radiance(v, s, p.turbidity, p.scale, p.night) + extras(v, s, sun_color, p, time, pixel_angle)


def extras(v, s, sun_color, p: SkySettings, time: float, pixel_angle: float) -> np.ndarray:
    """(..., 3) what both skies draw over their radiance (``shaders/sky/extras.glsl``): the sun disc
    and glare and (if ``p.stars``) the stars, dimmed below the horizon; unit ``v`` (..., 3), ``s`` (3,)."""
    extra = sun_disc(v, s, sun_color, p.sun_size_deg, p.sun_gain, p.sun_glare, pixel_angle)
    if p.stars:
        extra = extra + star_field(v, s[1], time, pixel_angle, p.star_density, p.star_brightness, p.twinkle)
    return extra * below_horizon(v[..., 1])[..., None]


def physical_sky_color(view_dir, sun_dir, sun_color, sky_view_lut, altitude: float = 0.0,
                       settings: SkySettings | None = None, time: float = 0.0, pixel_angle: float = 0.0) -> np.ndarray:
    """(..., 3) what the physical sky pass (``shaders/sky/physical_pixel.glsl``) writes: the sky-view LUT
    ``sky_view_lut`` (from :func:`atmos.plugins.sky.atmosphere.sky_view_lut`, or read back from the
    GPU) along ``view_dir``, ``night`` × (1 − :func:`daylight`), and the :func:`extras`."""
    from atmos.plugins.sky.atmosphere import sample_sky_view
    p = settings or SkySettings(model="physical")
    v = unit_vectors(view_dir, "view_dir")
    s = unit_vectors(sun_dir, "sun_dir").reshape(3)
    rgb = sample_sky_view(p.atmosphere, sky_view_lut, altitude, v, s)
    rgb = rgb + np.asarray(p.night, np.float64) * (1.0 - daylight(s[1]))
    return rgb + extras(v, s, sun_color, p, time, pixel_angle)
