"""Soft particles: a cloud sprite that meets terrain fades out across its depth span (sprite.frag) instead
of cutting a hard line, on screen and off screen — its contact no harder than the ray march of the same
volume and where the volume's is — and the fade matches its float64 reference."""
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from atmos import App, DefaultPlugins, create_headless
from atmos.camera import Camera
from atmos.lighting import Sun
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.sprites.reference import soft_fade
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.clouds.weather import VolumeOrigin

OUT = Path(__file__).resolve().parents[1] / "out"


def column_on_ground(gpu, renderer):
    """A dense 40 m column of cloud standing 40 m deep in the ground plane, seen from above at 34°."""
    density = np.zeros((16, 6, 16), np.float32)
    density[7:9, :, 7:9] = 3.0
    settings = CloudSettings(cell_size=(20.0, 20.0, 20.0), base_altitude=-40.0, group_size=(8, 8),
                             smoothing_slices=1, sigma_t=0.05)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(tile=1e4),
                               CloudsPlugin(settings, density=density), renderer)
    origin = app.resource(VolumeOrigin)
    origin.x, origin.z = 0.0, 0.0
    app.insert_resource(Sun.from_angles(40.0, 70.0))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([160.0, 160.0, 400.0])
    cam.look_at(np.array([160.0, 0.0, 160.0]))
    cam.near, cam.far = 1.0, 5000.0
    app.run_frames(2)
    return app


def contact_profile(renderer, name):
    """The column's middle band (row means, top to bottom) and the bare scene's, as HDR linear colour."""
    gpu = create_headless((200, 150))
    app = column_on_ground(gpu, renderer)
    try:
        img = app.read_linear()[..., :3].astype(np.float64)        # row 0 at the top
        OUT.mkdir(exist_ok=True)
        Image.fromarray((np.clip(img, 0, 1) ** (1 / 2.2) * 255).astype(np.uint8)).save(OUT / f"soft_particles_{name}.png")
        renderer.configure(enabled=False)
        app.render()
        bare = app.read_linear()[..., :3].astype(np.float64)       # the ground and sky alone
        w = img.shape[1]
        return img[:, w // 2 - 8:w // 2 + 8].mean((1, 2)), bare[:, w // 2 - 8:w // 2 + 8].mean((1, 2))
    finally:
        app.close()
        gpu.release()


@pytest.fixture(scope="module")
def marched_contact():
    """The same column ray-marched in 4 m steps: the volume's own contact with the ground (an opaque
    column standing in the ground has a real edge there; sprites must not add a harder one)."""
    band, bare = contact_profile(RaymarchCloudsPlugin(resolution=1, jitter=False, detail_octaves=0, steps=1024,
                                                      step=0.2, step_growth=0.0), "march")
    return band, np.flatnonzero(np.abs(band - bare) > 0.01).max()


@pytest.mark.parametrize("downsample", [1, 2])
def test_a_sprite_column_on_the_ground_shows_no_hard_contact_line(downsample, marched_contact):
    band, bare = contact_profile(CloudRenderPlugin(downsample=downsample), str(downsample))
    march, march_low = marched_contact
    cloud = np.abs(band - bare)
    assert cloud.max() > 0.1, "the column stands out against the ground"
    low = np.flatnonzero(cloud > 0.01).max()                        # the contact: the lowest cloud rows
    assert abs(low - march_low) <= 6, f"the sprites end at row {low}, the volume at row {march_low}"
    step = np.abs(np.diff(band[low - 16:low + 4])).max()
    march_step = np.abs(np.diff(march[march_low - 16:march_low + 4])).max()
    assert step < 0.75 * march_step, (f"a hard line where the sprites meet the ground: a step of {step:.3f} "
                                      f"in one row (the ray march's own edge: {march_step:.3f})")


def test_soft_fade_reference_fades_over_the_radius_and_never_nans():
    near, far = 0.5, 1e6
    depth = lambda z: (1.0 / near - 1.0 / z) / (1.0 / near - 1.0 / far)      # window depth of view depth z
    got = soft_fade(depth(np.array([70.0, 80.0, 90.0, 100.0, 110.0, 120.0, 1e5])), 100.0, 20.0, near, far)
    assert np.allclose(got, [0.0, 0.0, 0.25, 0.5, 0.75, 1.0, 1.0], atol=1e-6)
    assert np.isfinite(soft_fade(np.array([0.0, 1.0]), 1e9, 1e-3, near, far)).all()
