"""The example game, played headless with scripted input: a crate collected disappears and scores, banking
turns, a crash resets the round; the frames show the scene, the glider and the HUD."""
from pathlib import Path

import numpy as np

from atmos import Input, Transform, key
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.plugins.text import Label
from atmos.render_core import CapturePass
from atmos.runner import build_app

GAME = Path(__file__).parent.parent / "demos" / "glider.py"


def frames_until(app, done, limit):
    for n in range(limit):
        app.update(1 / 30)
        if done():
            return n + 1
    raise AssertionError(f"not within {limit} frames")


def test_the_glider_game_plays_headless():
    from atmos.demos.glider import CRATES, START, Game
    gpu = create_headless((96, 54))
    capture = CapturePass()
    try:
        app = build_app("glider", DemoSettings(size=gpu.size, headless=True), gpu, start=False)
        app.graph.add_pass(capture)
        app.run_frames(2, 1 / 30)
        game, inp = app.resource(Game), app.resource(Input)
        glider = app.world.component_for_entity(game.glider, Transform)
        score = app.world.component_for_entity(game.hud["score"], Label)
        assert score.text == f"crates 0/{CRATES}" and len(game.crates) == CRATES
        assert capture.depth[27, 48] < 1.0, "the chase camera has the glider in the middle of the frame"
        assert gpu.read_pixels().std() > 10

        # fly into the first crate: it is collected, scores and is gone from the world and the frame
        crate = game.crates[0]
        where = app.world.component_for_entity(crate, Transform).position
        glider.teleport(where + (0.0, 0.0, 40.0), yaw=0.0, pitch=0.0, roll=0.0)
        frames_until(app, lambda: game.score == 1, 30)
        app.update(1 / 30)
        assert not app.world.has_entity(crate) and crate not in game.crates and score.text == f"crates 1/{CRATES}"
        meshes = next(p for p in app.plugins if type(p).__name__ == "MeshPlugin")
        assert sum(len(rows) for rows in meshes.instances.values()) == 1 + CRATES - 1

        # bank right: the glider rolls and turns right (yaw grows)
        yaw = glider.yaw
        inp.press(key.D)
        app.run_frames(20, 1 / 30)
        inp.release(key.D)
        assert glider.roll > 0.3 and glider.yaw > yaw + 0.05

        # dive into the hills: the round starts again
        ground = game.terrain.height_at(glider.position[0], glider.position[2])
        glider.teleport((glider.position[0], ground + 15.0, glider.position[2]), pitch=-0.6)
        inp.press(key.W)
        frames_until(app, lambda: game.crashes == 1, 60)
        inp.release(key.W)
        assert game.score == 0 and len(game.crates) == CRATES
        np.testing.assert_allclose(glider.position, START, atol=3.0)
        app.update(1 / 30)
        message = app.world.component_for_entity(game.hud["message"], Label)
        assert message.text.startswith("crashed")

        # the HUD is on the frame: the same frame without its labels differs where they are
        with_hud = gpu.read_pixels().astype(int)
        for e in game.hud.values():
            app.world.component_for_entity(e, Label).text = ""
        next(p for p in app.plugins if type(p).__name__ == "TextPlugin").labels = []
        app.render()                                             # the same scene, drawn again
        without = gpu.read_pixels().astype(int)
        assert np.abs(with_hud - without)[:12, :48].max() > 60, "the score label top left"
        assert gpu.ctx.error == "GL_NO_ERROR"
        from PIL import Image
        Image.fromarray(with_hud.astype(np.uint8)).resize((384, 216)).save("out/glider_test.png")
        app.close()
    finally:
        gpu.release()


def test_the_example_game_is_small_and_makes_no_gl_calls():
    source = GAME.read_text()
    assert len(source.splitlines()) < 150
    for gl in ("moderngl", "pyglet", "ctx.", "glDraw", ".program(", "shader"):
        assert gl not in source, gl
