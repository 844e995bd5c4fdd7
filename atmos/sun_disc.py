"""The sun's disc as every sky draws it (``shaders/lib/sun_disc.glsl``), and its float64 twin.

The disc has the real sun's angular radius (settable), measured as the chord ``|v − s|`` so that a
float32 shader resolves it; it is limb-darkened as ``μ^SUN_LIMB`` per channel (μ = cos of the angle on
the solar surface, at least ``LIMB_FLOOR``) and antialiased over one pixel (at least ``EDGE_MIN`` of
its radius); a glare ``glare · (r / max(c, r))²`` of the centre's radiance falls as 1/angle² outside
it and fades out by the chord ``GLARE_REACH``. The physical and Preetham skies and the gradient sky
draw it with these constants, handed to the GLSL as defines (:data:`SUN_DISC_DEFINES`)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, num_field
from atmos.glsl_math import smoothstep

SUN_LIMB = (0.397, 0.503, 0.652)   # limb darkening I(μ) = μ^a per channel (red, green, blue)
LIMB_FLOOR = 0.25                  # the μ the disc's very edge is given (its last pixel stays lit)
GLARE_REACH = 0.2                  # chord |v − s| (≈ 11.5°) by which the glare has faded to 0
EDGE_MIN = 0.05                    # narrowest antialiased edge, as a fraction of the disc's radius
SUN_RADIUS_DEG = 0.2665            # the real sun's angular radius (0.53° across)
SUN_DISC_DEFINES = {"SUN_LIMB": "vec3({}, {}, {})".format(*SUN_LIMB), "LIMB_FLOOR": repr(LIMB_FLOOR),
                    "GLARE_REACH": repr(GLARE_REACH), "EDGE_MIN": repr(EDGE_MIN)}


@dataclass(frozen=True)
class SunDiscSettings(CheckedSettings):
    """The sun disc's look, declared once: every sky that draws the disc has these fields first (its
    settings class inherits them; all live)."""
    sun_size_deg: float = num_field(SUN_RADIUS_DEG, 0.0, 5.0, "angular radius of the sun disc in degrees (the real "
                                    "sun's: 0.2665°, 0.53° across)", lo_open=True)
    sun_gain: float = num_field(20.0, 0.0, 1e4, "radiance at the disc's centre per unit of the Sun resource's "
                                "colour (limb-darkened toward the edge)")
    sun_glare: float = num_field(0.05, 0.0, 1.0, "the glare round the disc, as a fraction of the centre's "
                                 "radiance at the disc's edge (falling as 1/angle² beyond it)")


def disc_chord(size_deg: float) -> float:
    """Chord length |v − s| of the disc's angular radius ``size_deg``."""
    return 2.0 * math.sin(0.5 * math.radians(size_deg))



def sun_disc(view_dir, sun_dir, sun_color, size_deg: float, gain: float, glare: float = 0.0,
             pixel_angle: float = 0.0) -> np.ndarray:
    """(..., 3) radiance of the disc and its glare for unit ``view_dir`` (..., 3) and ``sun_dir``: ``gain ·
    sun_color`` at the centre (module docstring; ``pixel_angle``: radians per pixel)."""
    c = np.linalg.norm(np.asarray(view_dir, np.float64) - np.asarray(sun_dir, np.float64), axis=-1)[..., None]
    r = disc_chord(size_deg)
    half = 0.5 * max(pixel_angle, EDGE_MIN * r)
    cover = 1.0 - smoothstep(r - half, r + half, c)
    mu = np.sqrt(np.maximum(1.0 - (c / r) ** 2, LIMB_FLOOR ** 2))
    halo = glare * (r / np.maximum(c, r)) ** 2 * (1.0 - smoothstep(0.0, GLARE_REACH, c))
    return gain * (cover * mu ** np.array(SUN_LIMB) + halo) * np.asarray(sun_color, np.float64)
