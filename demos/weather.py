"""weather: sunny to overcast and back, by changing the cloud density over time."""
import math

import numpy as np

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.demos._cloudscape import build_cloudscape
from atmos.plugins.weather import WeatherParams

TITLE = "sunny to overcast and back: the cloud density target rises and falls over time"
DEFAULT_FRAMES = 360
SUNNY, OVERCAST = 20, 700      # ellipsoids
PERIOD = 24.0                  # seconds for sunny → overcast → sunny


def change_weather(app) -> None:
    phase = 0.5 - 0.5 * math.cos(2 * math.pi * app.clock.frame_time / PERIOD)
    app.resource(WeatherParams).cloud_density = int(round(SUNNY + (OVERCAST - SUNNY) * phase))


def look_up(app) -> None:
    if app.resource(DemoSettings).headless:
        cam = app.resource(Camera)
        cam.yaw, cam.pitch = 0.6 + 0.02 * app.clock.frame_time, math.radians(14.0)


def build(app, settings) -> None:
    build_cloudscape(app, settings, hours=13.0, cloud_density=SUNNY, warmup_steps=10)
    app.resource(WeatherParams).density_adaption = 40
    app.resource(Camera).position = np.array([0.0, 200.0, 0.0])
    app.add_system(change_weather, "update", label="change_weather")
    app.add_system(look_up, "update", label="look_up", after="fly_camera")
