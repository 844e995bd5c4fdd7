"""cloud_field: clouds forming from an empty sky and staying stable, seen from the top."""
from atmos.defaults import DefaultPlugins
from atmos.plugins.clouds import CloudSettings, CloudsPlugin, CloudTopViewPlugin
from atmos.plugins.clouds.weather import WeatherSettings

TITLE = "the cloud automaton forming clouds from an empty sky, top view of the summed slices"
DEFAULT_FRAMES = 300


def build(app, settings) -> None:
    weather = WeatherSettings(volume_shape=(128, 16, 128), cloud_density=120, density_adaption=4, cloud_size=7.0,
                              cloud_size_variance=2.5, region_margin=12.0, lifetime=200.0, lifetime_variance=60.0,
                              hum_scale=0.2, act_scale=0.01, ext_scale=0.1, altitude=0.5, altitude_variance=0.1,
                              vertical_scale=0.45, wind=(0.6, 0.0, 0.25))
    app.add_plugins(DefaultPlugins(overlay=not settings.headless),
                    CloudsPlugin(CloudSettings(weather=weather, smoothing_slices=4, group_size=(32, 32)),
                                 seed=settings.seed),
                    CloudTopViewPlugin())
    app.frames.slices_per_frame = 3       # 10 slices per step: a new step every ~4 frames
