"""The scene's opaque pieces (terrain, ground, meshes) take the sky's light from the Sun resource's
``ambient``, the one the sky model (DaylightPlugin or the physical sky) writes: no fixed ambient."""
import numpy as np
import pytest

from atmos import App, Camera, DefaultPlugins, Sun
from atmos.gpu import create_headless
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.terrain import TerrainPlugin
from atmos.render_core import CapturePass, RenderCorePlugin

W, H = 48, 32


def ground_pixels(gpu, piece, ambient):
    """Mean linear colour of the lower rows, the sun below the horizon (so only the ambient lights)."""
    app = App(gpu)
    capture = CapturePass()
    app.insert_resource(Sun(direction=np.array([0.0, -0.5, 1.0]), color=(0.0, 0.0, 0.0), ambient=ambient))
    app.add_plugins(DefaultPlugins(overlay=False, fly_camera=False), piece)
    next(p for p in app.plugins if isinstance(p, RenderCorePlugin)).configure(dither=False)
    app.graph.add_pass(capture)
    cam = app.resource(Camera)
    cam.position, cam.yaw, cam.pitch, cam.roll = np.array([0.0, 60.0, 0.0]), 0.0, -0.6, 0.0
    app.run_frames(1)
    rgb = capture.color[::-1][H // 2:, :, :3].reshape(-1, 3).astype(np.float64).mean(0)
    app.close()
    return rgb


@pytest.mark.parametrize("make", [GroundPlugin, TerrainPlugin], ids=["ground", "terrain"])
def test_opaque_scene_is_lit_by_the_suns_ambient(make):
    gpu = create_headless((W, H))
    try:
        blue = ground_pixels(gpu, make(), (0.0, 0.0, 0.5))
        twice = ground_pixels(gpu, make(), (0.0, 0.0, 1.0))
        dark = ground_pixels(gpu, make(), (0.0, 0.0, 0.0))
    finally:
        gpu.release()
    assert blue[2] > 1e-3 and blue[0] < 1e-6 and blue[1] < 1e-6      # only the ambient's channel is lit
    np.testing.assert_allclose(twice, 2.0 * blue, rtol=1e-3, atol=1e-6)   # in proportion to it
    np.testing.assert_allclose(dark, 0.0, atol=1e-6)                  # no light of its own at night
