"""sky_layer: the 2D dynamic cloud layer drifting over a sky gradient and the ground."""
import numpy as np

from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.demo_registry import DemoSettings
from atmos.lighting import Sun
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.sky_layer import SkyLayerPlugin

TITLE = "2D dynamic cloud layer: four scrolling tileable octaves, emptiness/sharpness, sun-lit via RGBA light march"
DEFAULT_FRAMES = 90


def turn_camera(app) -> None:
    """Headless runs pan slowly across the sky; in a window the fly camera is yours."""
    if not app.resource(DemoSettings).headless:
        return
    cam = app.resource(Camera)
    cam.yaw = 0.4 + 0.05 * app.clock.frame_time
    cam.pitch = 0.45


def build(app, settings) -> None:
    app.insert_resource(Sun.from_angles(elevation_deg=25.0, azimuth_deg=30.0))
    app.add_plugins(DefaultPlugins(overlay=not settings.headless), SkyGradientPlugin(), GroundPlugin(),
                    SkyLayerPlugin(seed=settings.seed))
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 2.0, 0.0])
    cam.yaw, cam.pitch = 0.4, 0.45
    app.add_system(turn_camera, "update", label="turn_camera", after="fly_camera")
