"""A cloud layer for tests, benchmarks and screenshots: weather with a chosen number of clouds."""
from __future__ import annotations

from atmos.plugins.clouds.weather.settings import WeatherSettings


def example_weather(shape=(64, 16, 64), cloud_density: int = 60, **overrides) -> WeatherSettings:
    """Cumulus-like weather over ``shape`` cells; ``cloud_density`` (ellipsoids) sets the cover;
    ``overrides``: any other WeatherSettings field (``density_adaption`` = ellipsoids added per step)."""
    scale = max(shape[0], shape[2]) / 64.0
    settings = WeatherSettings(volume_shape=tuple(shape), cloud_density=cloud_density, density_adaption=4,
                               cloud_size=7.0 * scale ** 0.5, cloud_size_variance=2.5 * scale ** 0.5,
                               region_margin=12.0 * scale, lifetime=200.0, lifetime_variance=60.0, hum_scale=0.2,
                               act_scale=0.01, ext_scale=0.1, altitude=0.5, altitude_variance=0.1,
                               vertical_scale=0.45, wind=(0.6, 0.0, 0.25))
    return settings.replace(**overrides) if overrides else settings
