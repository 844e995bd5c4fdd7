"""testbed: ground plane, sky gradient and an animated template volume through the sliced scheduler."""

import numpy as np

from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.demo_registry import DemoSettings
from atmos.lighting import Sun
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.template_volume import TemplateVolumePlugin

TITLE = "ground, sky gradient and an animated volume updated over frames through three texture sets"
DEFAULT_FRAMES = 90


def orbit_camera(app) -> None:
    """Headless runs circle the volume slowly; in a window the fly camera is yours."""
    if not app.resource(DemoSettings).headless:
        return
    app.resource(Camera).orbit((0.0, 6.0, 0.0), 34.0, 12.0, 0.6 + 0.15 * app.clock.frame_time)


def build(app, settings) -> None:
    app.insert_resource(Sun.from_angles(elevation_deg=35.0, azimuth_deg=40.0))
    app.add_plugins(DefaultPlugins(overlay=not settings.headless), SkyGradientPlugin(), GroundPlugin(),
                    TemplateVolumePlugin())
    cam = app.resource(Camera)
    cam.position = np.array([20.0, 12.0, 30.0])
    cam.look_at((0.0, 6.0, 0.0))
    app.add_system(orbit_camera, "update", label="orbit_camera", after="fly_camera")
