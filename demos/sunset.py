"""sunset: a landscape with clouds forming, drifting and catching the low sun."""
import math

import numpy as np

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.demos._cloudscape import build_cloudscape
from atmos.lighting import Sun

TITLE = "clouds forming and drifting over a landscape at sunset, ground shadows, light shafts and haze"
DEFAULT_FRAMES = 240


def pan_toward_the_sun(app) -> None:
    """Headless runs look toward the setting sun and pan slowly; in a window the camera is yours."""
    if not app.resource(DemoSettings).headless:
        return
    sun = app.resource(Sun).direction
    azimuth = math.atan2(sun[0], -sun[2]) + 0.35 * math.sin(0.1 * app.clock.frame_time)
    cam = app.resource(Camera)
    cam.yaw, cam.pitch = azimuth, math.radians(7.0)


def build(app, settings) -> None:
    # the sun 2.2° up, setting in about half a minute of play (0.01 game hours a second)
    build_cloudscape(app, settings, hours=19.5, speed=0.01, cloud_density=150, warmup_steps=12, haze=True)
    app.resource(Camera).position = np.array([0.0, 320.0, 0.0])
    app.add_system(pan_toward_the_sun, "update", label="pan_toward_the_sun", after="daylight")
