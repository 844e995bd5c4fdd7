"""Input: held, pressed and released keys (pyglet constants), mouse, buttons and wheel, scripted headless;
the fly camera is optional and follows it."""
import numpy as np
import pytest

from atmos import App, Camera, DefaultPlugins, FlyCameraPlugin, Input, key, mouse


def test_keys_buttons_mouse_and_wheel_last_one_frame():
    app = App()
    app.add_plugins(DefaultPlugins(overlay=False))
    inp = app.resource(Input)
    seen = []
    app.add_system(lambda app: seen.append((set(inp.keys), set(inp.pressed), set(inp.released), inp.mouse,
                                            (inp.mouse_dx, inp.mouse_dy), set(inp.buttons_pressed), inp.wheel)),
                   "update", label="watch")
    inp.press(key.SPACE)
    inp.press(key.SPACE)                                       # a held key is not pressed again
    inp.move_mouse(10, 20)
    inp.move_mouse(15, 18)
    inp.press_button(mouse.LEFT)
    inp.scroll(2)
    app.update(1 / 60)
    inp.release(key.SPACE)
    app.update(1 / 60)
    app.update(1 / 60)
    (held, pressed, released, pos, motion, buttons, wheel), second, third = seen
    assert held == pressed == {key.SPACE} and not released
    assert pos == (15.0, 18.0) and motion == (15.0, 18.0) and buttons == {mouse.LEFT} and wheel == (0.0, 2.0)
    assert second[0] == set() and second[2] == {key.SPACE} and second[4] == (0.0, 0.0) and second[6] == (0.0, 0.0)
    assert third[2] == set() and inp.buttons == {mouse.LEFT}
    inp.clear()                                                # focus lost: everything let go
    assert not inp.buttons and inp.buttons_released == {mouse.LEFT}
    app.close()


def test_atmos_key_constants_are_pyglets():
    assert key.W == 119 and key.symbol_string(key._1) == "_1" and mouse.LEFT == 1


@pytest.mark.parametrize("call, args, words", [("press", ("w",), r"pyglet constant \(atmos\.key\.W"),
                                               ("press_button", (1.5,), "pyglet constant"),
                                               ("move_mouse", (float("nan"), 0), "finite numbers"),
                                               ("scroll", ("up",), "finite numbers")])
def test_bad_input_names_the_call(call, args, words):
    with pytest.raises(ValueError, match=rf"Input\.{call} takes .*{words}"):
        getattr(Input(), call)(*args)


def test_fly_camera_is_optional_and_moves_with_held_keys():
    for fly in (True, False):
        app = App()
        app.add_plugins(DefaultPlugins(overlay=False, fly_camera=fly))
        assert any(isinstance(p, FlyCameraPlugin) for p in app.plugins) == fly
        cam, inp = app.resource(Camera), app.resource(Input)
        start = cam.position.copy()
        inp.press(key.W)
        app.run_frames(10, 0.05)
        moved = cam.position - start
        if fly:
            np.testing.assert_allclose(moved, cam.forward() * 20.0 * 0.5, atol=1e-9)
        else:
            assert not moved.any()
        inp.release(key.W)
        inp.press_button(mouse.LEFT)
        yaw = cam.yaw
        inp.move_mouse(100, 0)
        app.update(0.05)
        assert (cam.yaw == pytest.approx(yaw + 0.4)) == fly     # a drag turns by `turn` per pixel
        app.close()
    with pytest.raises(ValueError, match="DefaultPlugins.fly_camera must be True or False"):
        DefaultPlugins(fly_camera="no")


def test_f1_shows_and_hides_the_frame_time_overlay(gpu, ctx):
    """The overlay toggles itself from Input (a window, a script or a test press F1 alike): the
    'overlay' pass is culled while hidden and kept once shown."""
    from atmos.overlay import OverlayPlugin
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False))
    overlay = next(p for p in app.plugins if isinstance(p, OverlayPlugin))
    kept = lambda: "overlay" in [p.name for p in app.graph.compile().order]
    inp = app.resource(Input)
    app.update(1 / 60)
    assert not overlay.settings.visible and not kept()
    for visible in (True, False):
        inp.press(key.F1)
        app.update(1 / 60)                     # toggled by this frame's system, drawn from the next frame
        inp.release(key.F1)
        app.update(1 / 60)
        assert overlay.settings.visible is visible and kept() is visible
    app.close()
