"""The README's "Writing a pass" example (examples/height_haze) runs through an App and matches a
float64 reference of its haze on the captured frame."""
import sys
from pathlib import Path

import numpy as np
import pytest

from atmos import App, Camera, CapturePass, DefaultPlugins, Plugin
from atmos.camera import view_basis
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "examples"))
from height_haze import HeightHazePlugin  # noqa: E402


class Capture(Plugin):
    def build(self, app):
        self.capture = app.graph.add_pass(CapturePass())


def frame(gpu, *plugins):
    capture = Capture()
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(), capture, *plugins)
    app.run_frames(1)
    camera = app.resource(Camera)
    result = capture.capture.color.copy(), capture.capture.depth.copy(), camera
    app.close()
    return result


def reference_transmittance(depth, camera, size, s):
    """T per pixel (rows bottom-up like the capture), float64, from the settings ``s``."""
    w, h = size
    u, v = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    basis = view_basis(camera, w / h)
    ray = np.stack([u * 2 - 1, v * 2 - 1, np.ones_like(u)], -1) @ basis.T
    n, f = camera.near, camera.far
    z = n / ((1 - depth) + depth * (n / f))
    dist = np.where(depth >= 1.0, s.max_distance, z * np.linalg.norm(ray, axis=-1))
    dy = ray[..., 1] / np.linalg.norm(ray, axis=-1)
    k = dy * dist / s.scale_height
    with np.errstate(divide="ignore", invalid="ignore"):
        along = np.where(np.abs(k) < 1e-6, dist, s.scale_height * -np.expm1(-k) / dy)
    tau = s.density * np.exp(-(camera.position[1] - s.base) / s.scale_height) * along
    return np.exp(-tau)


@pytest.mark.parametrize("density", [2e-4, 3e-3])
def test_height_haze_matches_its_float64_reference(fresh_gpu, density):
    plain, depth, camera = frame(fresh_gpu)
    haze = HeightHazePlugin(density=density, scale_height=50.0, base=0.0)
    hazed, _, _ = frame(fresh_gpu, haze)
    t = reference_transmittance(depth, camera, fresh_gpu.size, haze.settings)[..., None]
    expected = plain[..., :3] * t + np.asarray(haze.settings.haze_color) * (1 - t)
    assert 0.02 < float((1 - t).mean()) < 0.98, "the scene has haze to compare"
    np.testing.assert_allclose(hazed[..., :3], expected, rtol=4e-3, atol=2e-3)   # float16 colour target
    np.testing.assert_array_equal(hazed[..., 3], plain[..., 3])                  # haze keeps the sky occlusion
