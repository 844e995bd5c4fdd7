"""The gradient sky against its float64 twin, looking into the sun (the disc the real sun's size,
limb-darkened, with glare: atmos/sun_disc.py) and across the horizon."""
import dataclasses
import math

import numpy as np
import pytest

from atmos import App, DefaultPlugins
from atmos.camera import Camera
from atmos.lighting import Sun, unit_sun
from atmos.plugins.clouds.raymarch.reference import rays
from atmos.plugins.sky_gradient import SkyGradientPlugin, SkyGradientSettings, gradient_sky


@pytest.mark.parametrize("fov, elevation, settings", [
    (2.0, 12.0, {}), (2.0, 0.1, {}), (40.0, 8.0, dict(sun_size_deg=1.5, sun_glare=0.2, zenith=(0.1, 0.2, 0.9)))],
    ids=["disc", "setting", "wide"])
def test_the_gradient_sky_matches_float64(gpu, ctx, rng, fov, elevation, settings):
    """Every pixel within rgba16f's rounding (2^-11 relative) and float32's of the disc's edge: a pixel
    whose centre lies within a few float32 ulps of the chord of the edge may differ by the edge's slope."""
    sun = Sun.from_angles(elevation, float(rng.uniform(0, 360)), color=tuple(rng.uniform(0.5, 1.5, 3)))
    params = SkyGradientSettings(**settings)
    app = App(gpu).insert_resource(sun)
    app.add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(params))
    app.startup()
    cam = app.resource(Camera)
    cam.fov_y = math.radians(fov)
    s = unit_sun(sun.direction)
    cam.look_at(cam.position + s)
    image = app.read_linear()[::-1].astype(np.float64)
    app.close()
    dirs, _ = rays(cam, gpu.size)
    pixel = cam.fov_y / gpu.size[1]
    want = gradient_sky(dirs, s, sun.color, params, pixel)
    err = np.abs(image[..., :3] - want) / np.maximum(np.abs(want), 1e-3)
    edge = np.abs(np.linalg.norm(dirs - s, axis=-1) - 2 * math.sin(math.radians(params.sun_size_deg) / 2))
    ok = err.max(-1) <= 2 * 2.0 ** -11 + 1e-4
    assert np.all(ok | (edge < max(pixel, 0.05 * params.sun_size_deg * math.pi / 180) * 0.6)), err.max()
    assert (ok.mean()) > 0.97
    assert np.all(image[..., 3] == 0.0), "open sky"
    if fov == 2.0 and elevation > 1.0:
        bare = gradient_sky(dirs, s, sun.color, dataclasses.replace(params, sun_gain=0.0), pixel)
        disc = (image[..., :3] - bare) / np.asarray(sun.color)             # the disc and its glare alone
        h, w = gpu.size[1] // 2, gpu.size[0] // 2
        assert disc[h - 1:h + 1, w - 1:w + 1].mean() == pytest.approx(params.sun_gain * (1 + params.sun_glare), rel=0.01)
        radius = math.degrees(pixel) * np.sqrt((disc[..., 1] > 0.5 * params.sun_gain).sum() / math.pi)
        assert radius == pytest.approx(params.sun_size_deg, rel=0.1), "the real sun's size"


def test_the_sun_disc_settings_are_declared_once_and_checked():
    with pytest.raises(ValueError, match="SkyGradientSettings.sun_size_deg"):
        SkyGradientSettings(sun_size_deg=0.0)
    with pytest.raises(ValueError, match="SkyGradientSettings.sun_glare"):
        SkyGradientSettings(sun_glare=2.0)
    from atmos.plugins.sky.settings import SkySettings
    assert SkySettings().sun_size_deg == SkyGradientSettings().sun_size_deg == 0.2665
