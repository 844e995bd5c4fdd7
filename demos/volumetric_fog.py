"""volumetric_fog: a bank of ray-marched FBM fog drifting over the ground, lit by a low sun."""

import numpy as np

from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.demo_registry import DemoSettings
from atmos.lighting import Sun
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.volumetric_fog import VolumetricFogPlugin

TITLE = "ray-marched FBM volumetric fog with a light march toward the sun, occluded by the ground"
DEFAULT_FRAMES = 90
# a froxel volume averaged over frames (froxel_history): the error of about 48 steps per pixel at 1/17 of
# their cost at 960x540, and a cost that does not grow with the window (benchmarks/bench_volumetric_fog.py)
FOG = dict(scale=(5.0, 0.7, 5.0), frequency=0.09, absorption=0.2, octaves=7, steps=64, light_step=4.0,
           froxels=(256, 144, 64))


def orbit_camera(app) -> None:
    """Headless runs circle the fog bank slowly; in a window the fly camera is yours."""
    if not app.resource(DemoSettings).headless:
        return
    app.resource(Camera).orbit((0.0, 4.0, 0.0), 95.0, 14.0, 0.3 + 0.05 * app.clock.frame_time)


def build(app, settings) -> None:
    app.insert_resource(Sun.from_angles(elevation_deg=18.0, azimuth_deg=120.0))
    app.add_plugins(DefaultPlugins(overlay=not settings.headless), SkyGradientPlugin(), GroundPlugin(),
                    VolumetricFogPlugin(seed=settings.seed, **FOG))
    cam = app.resource(Camera)
    cam.position = np.array([28.0, 14.0, 91.0])
    cam.look_at((0.0, 4.0, 0.0))
    app.add_system(orbit_camera, "update", label="orbit_camera", after="fly_camera")
