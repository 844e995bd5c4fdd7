"""sky_day: a day–night cycle of the Preetham sky over the ground plane, facing the sun."""
import math

import numpy as np

from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.demo_registry import DemoSettings
from atmos.lighting import Sun
from atmos.plugins.daylight import DaylightPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky import SkyPlugin

TITLE = "Preetham analytic sky through a day–night cycle: sunset, twinkling stars, sunrise, noon"
DEFAULT_FRAMES = 360
HOURS_PER_SECOND = 2.5       # in full daylight or deep night; 5x slower with the sun near the horizon


def pacer(daylight: DaylightPlugin):
    """A system: time runs slower while the sun is near the horizon, so twilight lasts long enough to watch."""
    def pace_time(app) -> None:
        sun = app.get_resource(Sun)
        height = abs(float(sun.direction[1])) if sun is not None else 1.0
        daylight.configure(speed=HOURS_PER_SECOND * (0.2 + 0.8 * min(1.0, height / 0.3)))
    return pace_time


def face_the_sun(app) -> None:
    """Headless runs look along the sun's compass direction, just above the horizon; in a window the
    fly camera is yours."""
    if not app.resource(DemoSettings).headless:
        return
    s = app.resource(Sun).direction
    cam = app.resource(Camera)
    cam.yaw, cam.pitch = math.atan2(s[0], -s[2]), 0.18


def build(app, settings) -> None:
    daylight = DaylightPlugin(hours=17.0, speed=HOURS_PER_SECOND, latitude=45.0, day_of_year=172.0)
    app.add_plugins(DefaultPlugins(overlay=not settings.headless), daylight, SkyPlugin(), GroundPlugin())
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 2.0, 0.0])
    cam.fov_y = math.radians(70.0)
    app.add_system(pacer(daylight), "update", label="pace_time", before="daylight")
    app.add_system(face_the_sun, "update", label="face_the_sun", after="daylight")
