"""The Preetham, Shirley & Smits (1999) analytic sky from the Sun resource's direction, with a sun
disc, a night sky over twilight and optional twinkling stars; float64 numpy references of all of it.

``sky_radiance(view_dir, sun_dir, turbidity)`` gives the sky's colour in any direction (numpy), for
effects that want the sky's light; ``evaluate_sky`` computes the pass's colours on the GPU.
"""
from atmos.plugins.sky.settings import SkySettings
from atmos.plugins.sky.plugin import SkyPass, SkyPlugin
from atmos.plugins.sky.reference import sky_color, sky_radiance
from atmos.plugins.sky.shader import evaluate_sky

__all__ = ["SkySettings", "SkyPlugin", "SkyPass", "sky_radiance", "sky_color", "evaluate_sky"]
