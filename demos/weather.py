"""weather: sunny to overcast and back, by changing the cloud density over time; with the ray march
(the default) the cloud type follows: fair-weather cumulus, towering congestus as the sky fills,
a stratus deck when overcast; region by region (a CloudTypeMap), so some places tower before others."""
import math

import numpy as np

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.demos._cloudscape import build_cloudscape, region_offsets, regional_types
from atmos.plugins.clouds import CloudsPlugin
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.volume.shape import CLOUD_TYPES

TITLE = ("sunny to overcast and back: the cloud density target rises and falls over time (the ray march: cumulus, "
         "congestus, stratus with it)")
DEFAULT_FRAMES = 360
SUNNY, OVERCAST = 20, 700      # ellipsoids
PERIOD = 24.0                  # seconds for sunny → overcast → sunny
REGION_SPREAD = 0.3            # how far a region's type lies from the weather's at most


def cloud_type_at(phase: float) -> float:
    """The march's cloud type at ``phase`` (0 sunny, 1 overcast): cumulus, congestus at half, stratus."""
    cumulus, congestus, stratus = CLOUD_TYPES["cumulus"], CLOUD_TYPES["congestus"], CLOUD_TYPES["stratus"]
    if phase < 0.5:
        return cumulus + (congestus - cumulus) * 2.0 * phase
    return congestus + (stratus - congestus) * (2.0 * phase - 1.0)


def weather_changer(clouds: CloudsPlugin, march: RaymarchCloudsPlugin, offsets: np.ndarray):
    """A system: the cloud density target follows a slow cosine from sunny to overcast and back, the
    march's cloud types with it (:func:`cloud_type_at` in steps of 0.01, spread over the regions by
    :func:`~atmos.demos._cloudscape.regional_types`)."""
    current = [None]

    def change_weather(app) -> None:
        phase = 0.5 - 0.5 * math.cos(2 * math.pi * app.clock.frame_time / PERIOD)
        density = int(round(SUNNY + (OVERCAST - SUNNY) * phase))
        if density != clouds.settings.weather.cloud_density:
            clouds.configure(weather={"cloud_density": density})
        kind = round(cloud_type_at(phase), 2)
        if kind != current[0]:
            march.configure(cloud_type=kind, type_map=regional_types(kind, offsets, REGION_SPREAD))
            current[0] = kind
    return change_weather


def look_up(app) -> None:
    if app.resource(DemoSettings).headless:
        cam = app.resource(Camera)
        cam.yaw, cam.pitch = 0.6 + 0.02 * app.clock.frame_time, math.radians(14.0)


def build(app, settings) -> None:
    clouds = build_cloudscape(app, settings, hours=13.0, cloud_density=SUNNY, warmup_steps=10)
    clouds.configure(weather={"density_adaption": 40})
    app.resource(Camera).position = np.array([0.0, 200.0, 0.0])
    march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    app.add_system(weather_changer(clouds, march, region_offsets(settings.seed)), "update", label="change_weather")
    app.add_system(look_up, "update", label="look_up", after="fly_camera")
