"""Camera orientation: yaw/pitch/roll against an independent rotation, and every pass family honours roll
(a rolled camera renders the rolled image: roll π flips it, roll π/2 turns it a quarter)."""
import math

import numpy as np
import pytest

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.orientation import angles, basis
from atmos.runner import build_app


def rodrigues(axis, angle) -> np.ndarray:
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.identity(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


def reference_basis(yaw, pitch, roll) -> np.ndarray:
    """Start looking along −z (right +x, up +y); yaw turns about −y (toward +x), pitch about the
    turned right axis, roll about the turned forward axis (right-hand rule: right goes down)."""
    r = rodrigues((0, -1, 0), yaw)
    r = rodrigues(r @ [1, 0, 0], pitch) @ r
    r = rodrigues(r @ [0, 0, -1], roll) @ r
    return np.column_stack([r @ [1, 0, 0], r @ [0, 1, 0], r @ [0, 0, -1]])


def test_basis_matches_an_independent_rotation_and_angles_inverts_it(rng):
    for _ in range(200):
        yaw, pitch, roll = rng.uniform(-math.pi, math.pi), rng.uniform(-1.5, 1.5), rng.uniform(-math.pi, math.pi)
        b = basis(yaw, pitch, roll)
        np.testing.assert_allclose(b, reference_basis(yaw, pitch, roll), atol=1e-12)
        np.testing.assert_allclose(np.cross(b[:, 0], b[:, 1]), -b[:, 2], atol=1e-12)
        got = angles(b[:, 2], b[:, 1] + 0.3 * b[:, 2])          # an up not perpendicular to forward
        np.testing.assert_allclose(basis(*got), b, atol=1e-9)
    right_down = basis(0.0, 0.0, 0.3)[:, 0]
    assert right_down[1] < 0, "roll > 0 banks right: the right side goes down"


def test_camera_matrices_and_look_at_follow_roll():
    cam = Camera(position=np.array([1.0, 2.0, 3.0]), yaw=0.4, pitch=-0.2, roll=0.7)
    view = cam.view()
    np.testing.assert_allclose(view[:3, :3], cam.basis().T * [[1], [1], [-1]], atol=1e-12)
    np.testing.assert_allclose(view[:3, :3] @ cam.up(), [0, 1, 0], atol=1e-12)
    cam.look_at((5.0, 2.0, 3.0), up=(0.0, 0.0, 1.0))               # look along +x, screen up along +z
    np.testing.assert_allclose(cam.forward(), [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(cam.up(), [0, 0, 1], atol=1e-12)
    cam.look_at((1.0, 9.0, 3.0))                                    # straight up, roll kept
    assert cam.pitch == pytest.approx(math.pi / 2) and np.isfinite(cam.view()).all()


def night(app):
    from atmos.plugins.daylight import DaylightPlugin
    next(p for p in app.plugins if isinstance(p, DaylightPlugin)).configure(hours=1.0, speed=0.0)


def active_effects(app) -> dict:
    """What each cloudscape family drew this frame: the sprites and where the shafts' sun is."""
    from atmos.plugins.clouds.sprites import CloudRenderPlugin
    from atmos.plugins.light_shafts.plugin import LightShaftsPlugin
    from atmos.plugins.light_shafts.screen_sun import screen_sun
    from atmos.lighting import Sun
    sprites = next(p for p in app.plugins if isinstance(p, CloudRenderPlugin)).stats.sprites
    shafts = next(p for p in app.plugins if isinstance(p, LightShaftsPlugin))
    sun = screen_sun(app.resource(Camera), 1.0, app.resource(Sun).direction, shafts.settings)
    return {"sprites": sprites, "shafts": sun.strength}


# demo -> (what it covers, a setup run before the frames)
SCENES = {
    "sunset": ("terrain, physical sky, cloud sprites, cloud shadows, light shafts (screen_sun)", None),
    "sky_day": ("sky stars at night over the ground plane", night),
    "fog_valley": ("heterogeneous fog over terrain", None),
    "volumetric_fog": ("ray-marched volume (view_basis)", None),
    "testbed": ("template volume, ground, sky gradient", None),
    "sky_layer": ("2D cloud layer on the sky dome", None),
}


def rolled_frames(name, size=48):
    gpu = create_headless((size, size))
    # the sprites: the march's r x r sample pattern lies in screen space (a rolled frame samples other rays)
    app = build_app(name, DemoSettings(size=gpu.size, headless=True, clouds="sprites"), gpu)
    try:
        setup = SCENES[name][1]
        if setup is not None:
            setup(app)
        from atmos.render_core import RenderCorePlugin
        next(p for p in app.plugins if isinstance(p, RenderCorePlugin)).configure(dither=False)  # per-pixel noise
        from atmos.plugins.light_shafts import LightShaftsPlugin
        for shafts in (p for p in app.plugins if isinstance(p, LightShaftsPlugin)):
            shafts.configure(steps=128, downsample=1)   # the march's jitter and low-res blocks are screen-space patterns
        from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
        for march in (p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin)):
            march.configure(resolution=1, jitter=False)  # the far field's march: r x r blocks and jitter too
        from atmos.plugins.antialias import AntialiasPlugin
        for aa in (p for p in app.plugins if isinstance(p, AntialiasPlugin)):
            aa.configure(mode="none")                   # the temporal mode's jitter is a screen-space offset
        app.run_frames(4, 1 / 30)
        cam = app.resource(Camera)
        if name == "sky_day":
            cam.pitch = 0.4                       # up among the stars, the horizon at the bottom
        frames = {}
        for roll in (0.0, math.pi / 2, math.pi):
            cam.roll = roll
            app.render()
            assert gpu.ctx.error == "GL_NO_ERROR"
            frames[roll] = gpu.read_pixels().astype(float)
        effects = active_effects(app) if name == "sunset" else {}
        return frames, effects
    finally:
        app.close()
        gpu.release()


@pytest.mark.parametrize("name", sorted(SCENES))
def test_a_rolled_camera_renders_the_rolled_image(name):
    frames, effects = rolled_frames(name)
    level, quarter, half = frames[0.0], frames[math.pi / 2], frames[math.pi]
    from PIL import Image
    Image.fromarray(np.hstack([level, quarter, half]).astype(np.uint8)).save(f"out/camera_roll_{name}.png")
    for turned in (level[::-1, ::-1], np.rot90(level)):   # roll π/2: screen up = world right
        assert (np.abs(level - turned).max(-1) > 20).mean() > 0.02, "a symmetric level image proves nothing"
    for got, want in ((half, level[::-1, ::-1]), (quarter, np.rot90(level))):
        diff = np.abs(got - want)
        off = (diff.max(-1) > 4).mean()           # 8-bit rounding of the sprites' blend: a pixel or two
        assert diff.mean() < 0.5 and off < 1e-3 and diff.max() <= 8, (SCENES[name][0], diff.mean(), off, diff.max())
    if name == "sunset":
        assert effects["sprites"] > 0 and effects["shafts"] > 0, effects
