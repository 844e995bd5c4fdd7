"""The Preetham, Shirley & Smits (1999) analytic sky from the Sun resource's direction, with a sun
disc, a night sky over twilight and optional twinkling stars; float64 numpy references of all of it.

``sky_radiance(view_dir, sun_dir, turbidity)`` gives the sky's colour in any direction (numpy), for
effects that want the sky's light; ``evaluate_sky`` computes the pass's colours on the GPU.

``SkySettings(model="physical")`` draws the physical sky after Hillaire 2020 instead
(:class:`AtmosphereSettings`, :mod:`.atmosphere` the float64 reference, :mod:`.luts` the GPU LUTs,
:mod:`.sun_light` the Sun's colour and ambient from the same model).
"""
from atmos.plugins.sky.atmosphere_settings import AtmosphereSettings
from atmos.plugins.sky.settings import MODELS, SkySettings
from atmos.plugins.sky.light import SkyLight
from atmos.plugins.sky.plugin import SkyPass, SkyPlugin
from atmos.plugins.sky.radiance import physical_sky_color, sky_color, sky_radiance
from atmos.plugins.sky.shader import evaluate_sky

__all__ = ["AtmosphereSettings", "MODELS", "SkyLight", "physical_sky_color", "SkySettings", "SkyPlugin", "SkyPass", "sky_radiance", "sky_color", "evaluate_sky"]
