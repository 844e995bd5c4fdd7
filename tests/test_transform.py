"""Transforms interpolated between fixed steps (clock.alpha: smooth at any frame rate) and the chase camera."""
import math

import numpy as np
import pytest

from atmos import App, Camera, ChaseCameraPlugin, DefaultPlugins, Transform


def moving_body(frame_dts, speed=3.0):
    """An entity moved by `speed` m/s along x in the fixed step; returns (drawn x, simulated x) per frame."""
    app = App(fixed_step=1 / 30)
    app.add_plugins(DefaultPlugins(overlay=False, fly_camera=False))
    body = app.world.create_entity(Transform())
    drawn, simulated = [], []

    def move(app):
        app.world.component_for_entity(body, Transform).position[0] += speed * app.clock.step

    def draw(app):
        t = app.world.component_for_entity(body, Transform)
        drawn.append(t.interpolated(app.clock.alpha).position[0])
        simulated.append(t.position[0])

    app.add_system(move, "simulate", label="move")              # added after the plugin: still after the snapshot
    app.add_system(draw, "render", label="draw")
    for dt in frame_dts:
        app.update(dt)
    app.close()
    return np.array(drawn), np.array(simulated), app


@pytest.mark.parametrize("fps", [60, 144, 45])
def test_interpolated_motion_is_smooth_at_any_frame_rate(fps):
    drawn, simulated, app = moving_body([1 / fps] * 120)
    steps = np.diff(drawn[10:])
    np.testing.assert_allclose(steps, 3.0 / fps, rtol=1e-6, atol=1e-9)  # even steps: no stutter
    raw = np.diff(simulated[10:])
    assert raw.std() > 0.3 * raw.mean(), "the fixed steps alone stutter (the test would prove nothing)"
    frame_time = np.arange(1, 121) / fps
    np.testing.assert_allclose(drawn[10:], 3.0 * (frame_time[10:] - 1 / 30), atol=1e-6)  # one step behind


def test_uneven_frames_stay_on_the_true_path():
    rng = np.random.default_rng(5)
    dts = rng.uniform(0.005, 0.05, 200)
    drawn, _, _ = moving_body(dts)
    np.testing.assert_allclose(drawn[20:], 3.0 * (np.cumsum(dts)[20:] - 1 / 30), atol=1e-6)


def test_angles_turn_the_short_way_and_teleports_do_not_smear():
    t = Transform(yaw=3.1)
    t.yaw = -3.1
    assert abs(t.interpolated(0.5).yaw) == pytest.approx(math.pi, abs=1e-9)
    t.teleport((100.0, 0.0, 0.0))
    assert t.interpolated(0.0).position == (100.0, 0.0, 0.0)
    assert t.interpolated(float("nan")).position == (100.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="Transform.scale"):
        Transform(scale=(1.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="Transform.position"):
        Transform(position=(0.0, float("inf"), 0.0))


def chase_app(**settings):
    app = App()
    chase = ChaseCameraPlugin(**settings)
    app.add_plugins(DefaultPlugins(overlay=False, fly_camera=False), chase)
    glider = app.world.create_entity(Transform(position=np.array([0.0, 100.0, 0.0]), yaw=0.3))
    chase.target = glider
    return app, chase, glider


def screen_of(cam, point):
    clip = cam.view_projection(1.0) @ np.append(point, 1.0)
    return clip[:2] / clip[3]


def test_the_chase_camera_sits_behind_and_keeps_the_target_in_view():
    app, chase, glider = chase_app(distance=12.0, height=3.0, look_ahead=0.0, stiffness=4.0, bank=0.5)
    cam = app.resource(Camera)
    t = app.world.component_for_entity(glider, Transform)

    def fly(app):
        t.position = t.position + 30.0 * app.clock.step * t.forward()

    app.add_system(fly, "simulate", label="fly")
    app.update(1 / 60)
    heading = np.array([math.sin(0.3), 0.0, -math.cos(0.3)])
    drawn = np.array(t.interpolated(app.clock.alpha).position)
    np.testing.assert_allclose(cam.position, drawn - 12.0 * heading + [0, 3.0, 0], atol=1e-9)   # snapped at first
    for _ in range(60):
        app.update(1 / 60)
        drawn = np.array(t.interpolated(app.clock.alpha).position)
        np.testing.assert_allclose(screen_of(cam, drawn), 0.0, atol=1e-9)   # aimed at the target every frame
    lag = np.linalg.norm(cam.position - (drawn - 12.0 * heading + [0, 3.0, 0]))
    assert 0.5 < lag < 10.0, "the eye trails smoothly at speed, not rigidly"
    t.roll = 0.6
    app.run_frames(2, 1 / 60)
    assert cam.roll == pytest.approx(0.3, abs=0.02), "bank 0.5 takes half the target's roll"
    app.world.delete_entity(glider)
    app.update(1 / 60)
    where = cam.position.copy()
    app.update(1 / 60)
    np.testing.assert_array_equal(cam.position, where)        # the target is gone: the camera stays
    app.close()


def test_chase_settings_are_checked():
    with pytest.raises(ValueError, match="ChaseCameraSettings.stiffness"):
        ChaseCameraPlugin(stiffness=0.0)
    with pytest.raises(ValueError, match="ChaseCameraSettings.bank"):
        ChaseCameraPlugin(bank=2.0)
