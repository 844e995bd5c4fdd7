"""Scripted runs: a script's step(app, frame) plays the game through Input, first in every frame;
--shots writes only the chosen frames, the same pixels as a full run's."""
import numpy as np
import pytest
from PIL import Image

from atmos import Input, key
from atmos.cli import main
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.runner import build_app, run_headless

SIZE = (64, 36)


def game(app, settings):
    """A tiny game: a system records, each frame, whether W is held and was pressed this frame."""
    from atmos import DefaultPlugins
    log = app.insert_resource([]).resource(list)
    app.add_plugins(DefaultPlugins(fly_camera=False))
    app.add_system(lambda app: log.append((key.W in app.resource(Input).keys, key.W in app.resource(Input).pressed)))


def played(frames, script=None):
    gpu = create_headless(SIZE)
    app = build_app(game, DemoSettings(size=SIZE, headless=True), gpu, script=script)
    try:
        for _ in range(frames):
            app.update(1 / 30)
        return app.resource(list)
    finally:
        app.close()
        gpu.release()


def test_a_script_plays_through_input_first_in_every_frame():
    seen = []

    def step(app, frame):
        seen.append(frame)
        if frame == 1:
            app.resource(Input).press(key.W)
        if frame == 3:
            app.resource(Input).release(key.W)

    assert played(5) == [(False, False)] * 5
    # the game's system sees the press in the frame the script made it (the script runs first), held after
    assert played(5, step) == [(False, False), (True, True), (True, False), (False, False), (False, False)]
    assert seen == [0, 1, 2, 3, 4]


def test_a_script_file_is_loaded_and_a_bad_one_is_refused(tmp_path):
    good = tmp_path / "play.py"
    good.write_text("from atmos import Input, key\n\ndef step(app, frame):\n"
                    "    if frame == 0:\n        app.resource(Input).press(key.W)\n")
    assert played(2, str(good)) == [(True, True), (True, False)]
    empty = tmp_path / "empty.py"
    empty.write_text("x = 1\n")
    for script, message in ((str(empty), "defines no step"), (str(tmp_path / "none.py"), "no such .py file"),
                            (3, r"must be a step\(app, frame\) function")):
        with pytest.raises(ValueError, match=message):
            played(1, script)


def test_shots_write_only_the_chosen_frames_with_the_pixels_of_a_full_run(tmp_path):
    settings = DemoSettings(size=SIZE, frames=9, headless=True)
    run_headless("testbed", settings, str(tmp_path / "all") + "/", progress=False)
    result = run_headless("testbed", settings, str(tmp_path / "shots") + "/", progress=False, shots="7,2")
    assert result["written"] == 2
    assert sorted(p.name for p in (tmp_path / "shots").iterdir()) == ["frame_00002.png", "frame_00007.png"]
    for n in (2, 7):
        shot = np.asarray(Image.open(tmp_path / "shots" / f"frame_{n:05d}.png"))
        assert np.array_equal(shot, np.asarray(Image.open(tmp_path / "all" / f"frame_{n:05d}.png"))), n


@pytest.mark.parametrize("argv, message", [
    (["--shots", "9"], "shot 9 is past the last frame (9 frames: 0..8)"),
    (["--shots", "-1"], "frame numbers >= 0"),
    (["--shots", "a,b"], "frame numbers such as 30,150,215"),
    (["--shots", "3", "--out", "{tmp}/x.mp4"], "the output must be a folder"),
])
def test_bad_shots_are_refused_before_anything_renders(capsys, tmp_path, argv, message):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    code = main(["demo", "testbed", "--headless", "--frames", "9", "--size", "32x18", "--quiet", *argv])
    assert code == 1 and message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
