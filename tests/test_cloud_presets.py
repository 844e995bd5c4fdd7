"""Cloud presets in metres, and a cloud volume that follows the camera by itself."""
import numpy as np
import pytest

from atmos import App, Camera, DefaultPlugins
from atmos.gpu import create_headless
from atmos.plugins.clouds.presets import PRESETS, SHAPE, CloudSky, cloud_settings
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.clouds.weather import VolumeOrigin


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_are_metres(name):
    p = PRESETS[name]
    s = cloud_settings(name)
    assert s.weather.volume_shape == SHAPE and s.base_altitude == p.altitude
    np.testing.assert_allclose(np.array(s.cell_size) * SHAPE, (p.extent, p.thickness, p.extent))
    assert cloud_settings(name, cover=1.0).weather.cloud_density > cloud_settings(name, cover=0.1).weather.cloud_density


def test_bad_preset_changes_are_named():
    with pytest.raises(ValueError, match="cloud_settings.preset must be one of"):
        cloud_settings("stormy")
    with pytest.raises(ValueError, match="cloud_settings.cover must be a finite number >= 0.0 and <= 1.0"):
        cloud_settings(cover=2.0)
    with pytest.raises(ValueError, match="cloud_settings has no field colour"):
        cloud_settings(colour=1)


def test_a_cloud_sky_forms_overhead_and_follows_the_camera():
    gpu = create_headless((48, 27))
    try:
        app = App(gpu)
        app.add_plugins(DefaultPlugins(overlay=False, fly_camera=False), SkyGradientPlugin(), CloudSky("broken"))
        cam = app.resource(Camera)
        cam.position, cam.pitch, cam.near, cam.far = np.array([5000.0, 300.0, -3000.0]), 0.9, 1.0, 20000.0
        app.run_frames(2, 1 / 30)
        settings = cloud_settings("broken")
        origin = app.resource(VolumeOrigin)
        centre = (np.array([origin.x, origin.z]) + np.array(SHAPE)[[0, 2]] / 2) * np.array(settings.cell_size)[[0, 2]]
        np.testing.assert_allclose(centre, cam.position[[0, 2]], atol=settings.cell_size[0])
        sky = gpu.read_pixels().astype(float)
        cam.position = cam.position + (800.0, 0.0, 0.0)
        app.update(1 / 30)
        assert origin.x == pytest.approx(np.floor(cam.position[0] / settings.cell_size[0] - SHAPE[0] / 2))
        app.close()
        plain = App(gpu)
        plain.add_plugins(DefaultPlugins(overlay=False, fly_camera=False), SkyGradientPlugin())
        plain.resource(Camera).position, plain.resource(Camera).pitch = np.array([5000.0, 300.0, -3000.0]), 0.9
        plain.run_frames(1)
        assert np.abs(sky - gpu.read_pixels()).mean() > 5, "clouds overhead from the first frames"
        plain.close()
    finally:
        gpu.release()
