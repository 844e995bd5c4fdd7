"""sky_day: a day–night cycle of the sky (the physical sky, or ``--sky preetham``) over the ground plane, facing the sun."""
import math

import numpy as np

from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.demo_registry import DemoSettings
from atmos.lighting import Sun
from atmos.plugins.daylight import DaylightPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.physical_camera import PhysicalCameraPlugin
from atmos.plugins.sky import SkyPlugin

TITLE = "the sky through a day–night cycle: sunset, Earth's shadow, twinkling stars, sunrise, noon"
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


EXPOSURE = (0.05, 1.0, 6.0)     # --exposure fixed, the physical sky: (sky-light luminance exposed at 1 and above, adaptation power, widest)
NIGHT_EV_RANGE = (-2.0, 14.0)   # --exposure auto: the camera's EV100 range (the night stays night: at most ~7x the day's exposure)


def expose_for_the_sky(app) -> None:
    """With the physical sky, twilight is ~100× darker than day: the exposure follows the sky's light
    like a camera's after sunset (``(Y0 / Y)^p`` of the ambient's luminance Y, within 1..max: 1 by day and at
    sunset), so the blue hour shows."""
    from atmos.render_core import RenderCorePlugin
    amb = np.asarray(app.resource(Sun).ambient, np.float64)
    y = max(float(amb @ (0.2126, 0.7152, 0.0722)), 1e-6)
    y0, power, widest = EXPOSURE
    core = next(p for p in app.plugins if isinstance(p, RenderCorePlugin))
    core.configure(exposure=min(max((y0 / y) ** power, 1.0), widest))


def build(app, settings) -> None:
    daylight = DaylightPlugin(hours=17.0, speed=HOURS_PER_SECOND, latitude=45.0, day_of_year=172.0)
    app.add_plugins(DefaultPlugins(overlay=not settings.headless), daylight, SkyPlugin(model=settings.sky), GroundPlugin())
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 2.0, 0.0])
    cam.fov_y = math.radians(70.0)
    app.add_system(pacer(daylight), "update", label="pace_time", before="daylight")
    app.add_system(face_the_sun, "update", label="face_the_sun", after="daylight")
    if settings.exposure == "auto":      # a camera metering the sky, quick (time runs fast); at night up to EV100 -2
        app.add_plugins(PhysicalCameraPlugin(ev_range=NIGHT_EV_RANGE, speed_up=4.0, speed_down=3.0))   # hours per second
    elif settings.sky == "physical":
        app.add_system(expose_for_the_sky, "update", label="expose_for_the_sky", after="sky_light")
