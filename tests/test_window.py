"""The window path under a virtual X server (Xvfb): frames render, ESC quits, resizing works."""
import os
import shutil
import subprocess
import sys
import time

import pytest

pytestmark = pytest.mark.skipif(shutil.which("Xvfb") is None, reason="Xvfb is not installed (setup.sh installs it)")


@pytest.fixture(scope="module")
def display():
    number = 90 + os.getpid() % 500
    server = subprocess.Popen(["Xvfb", f":{number}", "-screen", "0", "800x600x24"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(1.0)
    yield f":{number}"
    server.terminate()
    server.wait()


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
