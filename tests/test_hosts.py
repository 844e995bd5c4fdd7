"""atmos in GL contexts and windows a host owns: moderngl-window (input forwarded too) and Arcade under Xvfb (the pyglet host
is in test_window.py), and what a frame leaves bound for the host."""
import importlib.util
import os
import re
import shutil
import subprocess
import sys

import moderngl
import numpy as np
import pytest

import atmos
from atmos import App, DefaultPlugins, RenderPass
from atmos.graph import TextureDesc
from atmos.plugins.sky_gradient import SkyGradientPlugin

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")


class ScratchPass(RenderPass):
    """A readback-phase pass that draws into a framebuffer of its own, as captures do."""
    name = "scratch"
    phase = "readback"

    def setup(self, builder):
        builder.create("scratch", TextureDesc((8, 8)))
        builder.write("scratch")
        builder.side_effect()

    def execute(self, frame):
        fbo = frame.framebuffer(color=["scratch"])
        fbo.use()
        fbo.viewport = (0, 0, 2, 2)
        fbo.clear(0.0, 0.0, 0.0, 1.0)


def test_a_frame_ends_with_the_hosts_framebuffer_bound_at_full_size():
    gpu = atmos.create_headless((64, 40))
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin())
    app.graph.add_pass(ScratchPass())
    app.run_frames(2)
    assert gpu.ctx.fbo.glo == gpu.target.glo, "the last pass's framebuffer was left bound"
    assert gpu.ctx.viewport == (0, 0, 64, 40) and gpu.ctx.scissor == (0, 0, 64, 40)
    assert gpu.ctx.error == "GL_NO_ERROR"
    app.close()
    gpu.release()


def test_wrap_context_takes_a_moderngl_context_and_names_what_it_got():
    with pytest.raises(ValueError, match="wrap_context needs a moderngl.Context"):
        atmos.wrap_context("ctx", (64, 40))
    gpu = atmos.create_headless((8, 8))
    wrapped = atmos.wrap_context(gpu.ctx, (32, 16))    # a context someone else made and keeps
    assert not wrapped.headless and wrapped.size == (32, 16) and wrapped.target.glo == 0
    wrapped.resize((48, 20))
    assert wrapped.target.size == (48, 20) and wrapped.target.viewport == (0, 0, 48, 20)
    wrapped.release()
    assert not gpu.released
    gpu.release()


def test_a_software_rasterizer_in_a_window_says_so_once(capsys, monkeypatch):
    from atmos.gpu import context
    monkeypatch.setattr(context, "_NOTICED", [])
    gpu = atmos.create_headless((8, 8))
    assert "software rasterizer" not in capsys.readouterr().err, "headless runs (tests, renders) stay quiet"
    monkeypatch.setattr(context, "is_software", lambda ctx: True)
    for _ in range(2):
        atmos.wrap_context(gpu.ctx, (8, 8)).release()
    err = capsys.readouterr().err
    assert err.count("software rasterizer") == 1 and "frame times will be slow" in err, err
    monkeypatch.setattr(context, "is_software", lambda ctx: False)
    atmos.wrap_context(gpu.ctx, (8, 8)).release()
    assert capsys.readouterr().err == ""
    gpu.release()


# -- real hosts in windows -------------------------------------------------------------------------
needs_x = pytest.mark.skipif(shutil.which("Xvfb") is None, reason="Xvfb is not installed (setup.sh installs it)")


def run_host(display, tmp_path, example: str, package: str, frames: int = 6) -> tuple[np.ndarray, str]:
    """Run examples/EXAMPLE with pyglet's GL error checking on; its last frame as uint8 RGB and its stdout."""
    if importlib.util.find_spec(package) is None:
        pytest.skip(f"{package} is not installed (pip install -e '.[dev]' installs it)")
    from PIL import Image
    png = tmp_path / f"{package}.png"
    env = dict(os.environ, DISPLAY=display)
    env.pop("PYTHONOPTIMIZE", None)                          # -O would turn pyglet's debug_gl off
    proc = subprocess.run([sys.executable, os.path.join(EXAMPLES, example), str(frames), str(png)], env=env,
                          capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert f"host drew {frames} frames" in proc.stdout, proc.stdout + proc.stderr[-2000:]
    assert "gl error GL_NO_ERROR" in proc.stdout, proc.stdout
    return np.asarray(Image.open(png).convert("RGB")).astype(int), proc.stdout


def is_red(pixels):
    return (pixels[..., 0] > 200) & (pixels[..., 1] < 60) & (pixels[..., 2] < 60)


def is_sky(pixels):
    """Blue sky, or the white of a sunlit cloud (blue at most a little under red)."""
    return (pixels[..., 2] > 120) & (pixels[..., 2] >= pixels[..., 0] - 10)


@needs_x
def test_atmos_runs_inside_a_moderngl_window_config(display, tmp_path):
    frame, out = run_host(display, tmp_path, "moderngl_window_host.py", "moderngl_window")
    h, w, _ = frame.shape
    assert (w, h) == (320, 180)
    assert is_sky(frame[: h // 5]).mean() > 0.95, "atmos's sky is not at the top of the window"
    assert is_red(frame[h // 2 - 5: h // 2 + 5, w // 2 - 5: w // 2 + 5]).all(), "the host's triangle is missing"
    assert not is_red(frame[: h // 5]).any()
    seen = re.search(r"input keys \[(\d+)\] buttons \[(\d+)\] camera moved ([\d.]+)", out)    # events forwarded
    assert seen and int(seen[1]) == atmos.key.W and int(seen[2]) == atmos.mouse.LEFT, out
    assert float(seen[3]) > 0.0, "W held in the window did not fly atmos's camera"


@needs_x
def test_arcade_draws_its_sprites_and_text_over_atmos_sky(display, tmp_path):
    frame, _ = run_host(display, tmp_path, "arcade_host.py", "arcade")
    h, w, _ = frame.shape
    assert (w, h) == (320, 180)
    assert is_sky(frame[: h // 4]).mean() > 0.9, "atmos's sky is not at the top of the window"
    sprite = frame[h - 70: h - 30, 130: 190]                    # 60x40 at (160, 50), y up
    assert is_red(sprite[3:-3, 3:-3]).all(), "Arcade's sprite is missing"
    text = frame[h - 30:, :170]
    yellow = (text[..., 0] > 180) & (text[..., 1] > 180) & (text[..., 2] < 90)
    assert yellow.sum() > 50, "Arcade's text is missing"
