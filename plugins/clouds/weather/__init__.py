"""Weather ellipsoids and the region volume (thesis sec. 4.3.2-4.3.3).

* :class:`WeatherSettings` — the parameters of sec. 4.3.3.4, validated.
* :class:`Ellipsoid` — the ECS component of one weather ellipsoid, made checked with
  :func:`add_ellipsoid` (an invalid one made otherwise is removed by the next step, with a warning);
  :class:`VolumeOrigin` — where the simulation volume (the viewer) is.
* :func:`step_weather` — the five rules of sec. 4.3.3.5 for one step.
* :class:`RegionVolume` — the ellipsoids rendered into a float 3D texture on the GPU
  (value ``1 − r`` inside, 0 outside, max over ellipsoids), and the probabilities derived from it.
* :mod:`reference` — numpy float64 references of the region volume and the probabilities.
* :class:`WeatherPlugin` — the rules as the App ``simulate`` system ``"weather"``.
"""
from atmos.plugins.clouds.weather import reference
from atmos.plugins.clouds.weather.example import example_weather
from atmos.plugins.clouds.weather.components import COLUMNS, MAX_CELLS, Ellipsoid, VolumeOrigin, add_ellipsoid
from atmos.plugins.clouds.weather.settings import MAX_CLOUD_DENSITY, WeatherSettings
from atmos.plugins.clouds.weather.reference import probabilities, region_volume
from atmos.plugins.clouds.weather.region import RegionVolume
from atmos.plugins.clouds.weather.system import (StepReport, WeatherPlugin, ellipsoid_array, step_weather,
                                          wind_field_at)

__all__ = ["COLUMNS", "example_weather", "Ellipsoid", "MAX_CELLS", "add_ellipsoid", "MAX_CLOUD_DENSITY", "RegionVolume", "StepReport", "VolumeOrigin",
           "WeatherSettings", "WeatherPlugin", "ellipsoid_array", "probabilities", "reference",
           "region_volume", "step_weather", "wind_field_at"]
