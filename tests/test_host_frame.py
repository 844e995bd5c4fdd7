"""Compositing: a frame the game drew itself keeps its pixels; atmos draws the sky only where nothing was
drawn (depth 1) and fogs the game's geometry by its depth."""
import numpy as np
import pytest

from atmos import App, Camera, DefaultPlugins
from atmos.gpu import create_headless
from atmos.host_frame import HostFramePlugin, host_frame_reference
from atmos.plugins.fog import FogPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.render_core import CapturePass

W, H = 48, 32


def game_frame(rng):
    """What a game drew: a random colour where its depth < 1 (a disc), nothing (depth 1) elsewhere."""
    y, x = np.mgrid[0:H, 0:W]
    drawn = (x - 20) ** 2 + (y - 14) ** 2 < 100
    color = rng.integers(0, 256, (H, W, 4)).astype(np.uint8)
    depth = np.where(drawn, rng.uniform(0.9, 0.999, (H, W)), 1.0).astype(np.float32)
    return color, depth, drawn


def render(gpu, color, depth, *plugins, host=True, srgb=True):
    capture = CapturePass()
    tex = gpu.ctx.texture((W, H), 4, color.tobytes())
    dtex = gpu.ctx.depth_texture((W, H), depth.tobytes())
    dtex.compare_func = "<="                                 # the game's own setting, kept
    app = App(gpu)
    app.add_plugins(DefaultPlugins(overlay=False, fly_camera=False), *plugins,
                    *([HostFramePlugin(lambda: tex, dtex, srgb=srgb)] if host else []))
    from atmos.render_core import RenderCorePlugin
    next(p for p in app.plugins if isinstance(p, RenderCorePlugin)).configure(dither=False)
    app.graph.add_pass(capture)
    cam = app.resource(Camera)
    cam.position, cam.near, cam.far = np.array([0.0, 2.0, 0.0]), 0.5, 200.0
    app.run_frames(1)
    pixels = gpu.read_pixels()
    assert gpu.ctx.error == "GL_NO_ERROR" and dtex.compare_func == "<="
    app.close()
    tex.release()
    dtex.release()
    return capture.color[::-1], capture.depth[::-1], pixels        # rows top-down like the game's arrays


def test_the_sky_fills_only_what_the_game_left_empty(rng):
    gpu = create_headless((W, H))
    try:
        color, depth, drawn = game_frame(rng)
        got, got_depth, pixels = render(gpu, color[::-1], depth[::-1], SkyGradientPlugin())
        sky_only, _, _ = render(gpu, color[::-1], depth[::-1], SkyGradientPlugin(), host=False)
        want, want_depth = host_frame_reference(color / 255.0, depth, srgb=True)
        assert np.abs(got[drawn] - want[drawn]).max() < 2e-3, "the game's pixels, decoded from sRGB, alpha 1"
        np.testing.assert_allclose(got_depth, want_depth, atol=1e-6)
        np.testing.assert_allclose(got[~drawn], sky_only[~drawn], atol=1e-3)   # the sky, alpha 0, elsewhere
        assert (got[~drawn][:, 3] == 0).all() and np.abs(got[drawn] - sky_only[drawn]).max() > 0.1
        from PIL import Image
        Image.fromarray(pixels).resize((W * 4, H * 4), Image.NEAREST).save("out/host_frame_sky.png")
    finally:
        gpu.release()


def test_fog_covers_the_game_by_its_depth(rng):
    gpu = create_headless((W, H))
    try:
        color, depth, drawn = game_frame(rng)
        fog = dict(mode="exp", density=0.05, sky="keep")
        clear, _, _ = render(gpu, color[::-1], depth[::-1], SkyGradientPlugin())
        fogged, _, _ = render(gpu, color[::-1], depth[::-1], SkyGradientPlugin(), FogPlugin(**fog))
        assert np.abs(fogged[drawn] - clear[drawn]).mean() > 0.02, "the game's geometry is fogged"
    finally:
        gpu.release()


def test_bad_host_textures_are_named(gpu, ctx):
    with pytest.raises(ValueError, match="HostFramePlugin depth must be a depth texture"):
        HostFramePlugin(gpu.ctx.texture((4, 4), 4), gpu.ctx.texture((4, 4), 4))
