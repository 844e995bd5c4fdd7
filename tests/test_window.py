"""The window path under a virtual X server (Xvfb): frames render, ESC quits, resizing works."""
import math
import os
import shutil
import subprocess
import sys
import time

import pytest

pytestmark = pytest.mark.skipif(shutil.which("Xvfb") is None, reason="Xvfb is not installed (setup.sh installs it)")


def demo(display, *args):
    env = dict(os.environ, DISPLAY=display)
    return subprocess.Popen([sys.executable, "-m", "atmos", "demo", "testbed", "--size", "200x120", *args],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_window_renders_frames_and_exits(display):
    proc = demo(display, "--frames", "20")
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err


@pytest.mark.skipif(shutil.which("xdotool") is None, reason="xdotool is not installed")
def test_escape_quits_and_resize_is_safe(display):
    proc = demo(display)
    env = dict(os.environ, DISPLAY=display)
    window = ""
    for _ in range(100):
        window = subprocess.run(["xdotool", "search", "--name", "atmos"], env=env,
                                capture_output=True, text=True).stdout.split()
        if window:
            break
        time.sleep(0.2)
    assert window, "no window appeared"
    time.sleep(1.0)
    for size in (("1", "1"), ("300", "100")):
        subprocess.run(["xdotool", "windowsize", window[0], *size], env=env, check=True)
        time.sleep(0.5)
    subprocess.run(["xdotool", "windowfocus", window[0]], env=env, capture_output=True)  # no WM: may complain
    subprocess.run(["xdotool", "key", "Escape"], env=env, check=True)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err


def test_a_resized_window_is_filled_and_atmos_leaves_no_gl_error(display, tmp_path):
    """tests/window_probe.py grows and shrinks a window while running, reads each size's frame with
    read_pixels and then draws a pyglet Label with pyglet's GL error checking on; the render graph's
    timer queries run on GLX's functions."""
    import json
    env = dict(os.environ, DISPLAY=display)
    probe = os.path.join(os.path.dirname(__file__), "window_probe.py")
    proc = subprocess.run([sys.executable, probe, str(tmp_path)], env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout.strip().splitlines()[-1])
    seen, timers = report["seen"], report["timers"]
    assert [s["size"] for s in seen] == [[200, 120], [320, 240], [160, 200]]
    # the window's context is GLX's: the timer queries' functions resolve there, and their times come in
    assert timers["apis"] == ["glx"], timers
    ms = timers["ms"]
    assert ms and all(math.isfinite(v) and v >= 0.0 for v in ms.values()) and max(ms.values()) > 0.0, ms
    for s in seen:
        assert s["pixels"] == s["size"] and s["error"] == "GL_NO_ERROR", s
        assert s["dark"] < 0.01, f"the frame at {s['size']} does not fill the window ({s['dark']:.0%} left dark)"


GAME = '''
from atmos import DefaultPlugins
from atmos.plugins.sky_gradient import SkyGradientPlugin
TITLE = "a tiny game"

def build(app, settings):
    app.add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin())
'''


def test_atmos_run_opens_a_game_file_in_a_window(display, tmp_path):
    game = tmp_path / "tiny.py"
    game.write_text(GAME)
    env = dict(os.environ, DISPLAY=display)
    proc = subprocess.run([sys.executable, "-m", "atmos", "run", str(game), "--size", "160x90", "--frames", "8"],
                          env=env, capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "headless" not in proc.stderr and not (tmp_path / "out").exists(), "it ran headless, not in the window"


def test_the_example_game_runs_in_a_window(display, tmp_path):
    env = dict(os.environ, DISPLAY=display)
    game = os.path.join(os.path.dirname(__file__), "..", "demos", "glider.py")
    proc = subprocess.run([sys.executable, "-m", "atmos", "run", game, "--size", "160x90", "--frames", "6"],
                          env=env, capture_output=True, text=True, timeout=180, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert not (tmp_path / "out").exists(), "it ran headless, not in the window"


def test_atmos_runs_inside_a_pyglet_window_the_game_owns(display):
    env = dict(os.environ, DISPLAY=display)
    example = os.path.join(os.path.dirname(__file__), "..", "examples", "pyglet_host.py")
    proc = subprocess.run([sys.executable, example, "8"], env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "host drew 8 frames" in proc.stdout
