"""Running your own game: atmos.run(build) and `atmos run game.py` headless, bad game files, and a
display that is set but cannot be reached (headless with a notice)."""
import os
import subprocess
import sys

import numpy as np
import pytest

import atmos
from atmos.runner import display_problem, load_game

GAME = '''
import numpy as np
from atmos import Camera, DefaultPlugins
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.ground import GroundPlugin
TITLE = "a tiny game"
DEFAULT_FRAMES = 3

def build(app, settings):
    app.add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin())
    app.resource(Camera).position = np.array([0.0, 3.0, 0.0])
    app.insert_resource(np.random.default_rng(settings.seed))
'''


def run_cli(*args, cwd, env=None):
    return subprocess.run([sys.executable, "-m", "atmos", *args], capture_output=True, text=True, timeout=120,
                          cwd=cwd, env=dict(os.environ, **(env or {})))


def test_atmos_run_renders_a_game_file_headless(tmp_path):
    (tmp_path / "tiny.py").write_text(GAME)
    proc = run_cli("run", "tiny.py", "--headless", "--frames", "4", "--size", "64x36", "--out", "shot.png",
                   "--seed", "7", "--quiet", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "wrote 4 frames to shot.png" in proc.stdout
    from PIL import Image
    image = np.asarray(Image.open(tmp_path / "shot.png"))
    assert image.shape == (36, 64, 3) and image.std() > 3


@pytest.mark.parametrize("content, words", [(None, "no such .py file"),
                                            ("x = 1\n", "defines no build(app, settings)")])
def test_atmos_run_refuses_what_is_not_a_game(tmp_path, content, words):
    if content is not None:
        (tmp_path / "tiny.py").write_text(content)
    proc = run_cli("run", "tiny.py", "--headless", cwd=tmp_path)
    assert proc.returncode == 2 and words in proc.stderr, proc.stderr


def test_a_display_that_cannot_be_reached_renders_headless_with_a_notice(tmp_path):
    (tmp_path / "tiny.py").write_text(GAME)
    proc = run_cli("run", "tiny.py", "--size", "32x18", "--out", "x.png", "--quiet", cwd=tmp_path,
                   env={"DISPLAY": ":4321"})
    assert proc.returncode == 0, proc.stderr
    assert "DISPLAY=:4321 is set but no X server answers there; rendering headless" in proc.stderr
    assert (tmp_path / "x.png").is_file()


def test_display_problem_names_the_reason(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setenv("WAYLAND_DISPLAY", "wayland-0")
    assert "DISPLAY is not" in display_problem()
    monkeypatch.setenv("DISPLAY", ":4321")
    assert "no X server answers" in display_problem()


def test_atmos_run_takes_a_build_function_and_falls_back_to_headless(tmp_path, monkeypatch, capsys):
    from atmos.plugins.sky_gradient import SkyGradientPlugin
    built = []

    def build(app, settings):
        built.append(settings)
        app.add_plugins(atmos.DefaultPlugins(overlay=False), SkyGradientPlugin())

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    result = atmos.run(build, size=(48, 27), frames=2, out=str(tmp_path / "f.png"), seed=3)
    assert result["written"] == 2 and built[0].seed == 3 and built[0].headless and built[0].size == (48, 27)
    assert "no display" in capsys.readouterr().err
    with pytest.raises(ValueError, match="atmos.run size"):
        atmos.run(build, size=(0.5, 10), headless=True)
    with pytest.raises(ValueError, match="expected a demo name, a path"):
        load_game(42)


def test_rendering_into_a_file_is_headless_for_the_game_in_both_entry_points(tmp_path, monkeypatch):
    """``--out`` without ``--headless`` (and ``atmos.run(out=...)`` even with ``headless=False``) renders
    into the file and tells the game it is headless (demos script their camera then)."""
    game = GAME + "    (__import__('pathlib').Path('seen.txt')).write_text(str(settings.headless))\n"
    (tmp_path / "tiny.py").write_text(game)
    proc = run_cli("run", "tiny.py", "--frames", "1", "--size", "32x18", "--out", "a.png", "--quiet", cwd=tmp_path,
                   env={"DISPLAY": ""})
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "seen.txt").read_text() == "True"
    monkeypatch.chdir(tmp_path)
    (tmp_path / "seen.txt").unlink()
    atmos.run(str(tmp_path / "tiny.py"), size=(32, 18), frames=1, out=str(tmp_path / "b.png"), headless=False)
    assert (tmp_path / "seen.txt").read_text() == "True" and (tmp_path / "b.png").is_file()


def test_atmos_run_chooses_the_cloud_renderer_like_the_demo_option(tmp_path):
    """``atmos.run(..., clouds=...)`` reaches the game as ``settings.clouds`` (the cloud demos build that
    renderer: tests/test_demos.py); anything but "sprites" or "march" is refused before the game is built."""
    from atmos.plugins.sky_gradient import SkyGradientPlugin
    built = []

    def build(app, settings):
        built.append(settings.clouds)
        app.add_plugins(atmos.DefaultPlugins(overlay=False), SkyGradientPlugin())

    for clouds in ("march", "sprites"):
        atmos.run(build, size=(32, 18), frames=1, out=str(tmp_path / f"{clouds}.png"), clouds=clouds)
    atmos.run(build, size=(32, 18), frames=1, out=str(tmp_path / "default.png"))
    assert built == ["march", "sprites", "march"]             # the ray march unless told
    for bad in ("voxels", None, 2):
        with pytest.raises(ValueError, match=r"atmos\.run\.clouds must be one of 'sprites', 'march', got "):
            atmos.run(build, size=(32, 18), frames=1, headless=True, clouds=bad)
    with pytest.raises(ValueError, match=r"atmos\.run\.haze must be one of 'fog', 'air', 'both', got 'smoke'"):
        atmos.run(build, size=(32, 18), frames=1, headless=True, haze="smoke")
    with pytest.raises(ValueError, match=r"haze='air' is the physical sky's aerial perspective: it needs sky='physical'"):
        atmos.run(build, size=(32, 18), frames=1, headless=True, sky="preetham", haze="air")
    assert len(built) == 3, "refused before the game was built"
