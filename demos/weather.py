"""weather: sunny to overcast and back, by changing the cloud density over time."""
import math

import numpy as np

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.demos._cloudscape import build_cloudscape
from atmos.plugins.clouds import CloudsPlugin

TITLE = "sunny to overcast and back: the cloud density target rises and falls over time"
DEFAULT_FRAMES = 360
SUNNY, OVERCAST = 20, 700      # ellipsoids
PERIOD = 24.0                  # seconds for sunny → overcast → sunny


def weather_changer(clouds: CloudsPlugin):
    """A system: the cloud density target follows a slow cosine from sunny to overcast and back."""
    def change_weather(app) -> None:
        phase = 0.5 - 0.5 * math.cos(2 * math.pi * app.clock.frame_time / PERIOD)
        density = int(round(SUNNY + (OVERCAST - SUNNY) * phase))
        if density != clouds.settings.weather.cloud_density:
            clouds.configure(weather={"cloud_density": density})
    return change_weather


def look_up(app) -> None:
    if app.resource(DemoSettings).headless:
        cam = app.resource(Camera)
        cam.yaw, cam.pitch = 0.6 + 0.02 * app.clock.frame_time, math.radians(14.0)


def build(app, settings) -> None:
    clouds = build_cloudscape(app, settings, hours=13.0, cloud_density=SUNNY, warmup_steps=10)
    clouds.configure(weather={"density_adaption": 40})
    app.resource(Camera).position = np.array([0.0, 200.0, 0.0])
    app.add_system(weather_changer(clouds), "update", label="change_weather")
    app.add_system(look_up, "update", label="look_up", after="fly_camera")
