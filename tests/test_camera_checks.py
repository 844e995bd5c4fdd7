"""Bad camera values fail where they are set (or before the frame renders), naming the field and what
is allowed; nothing is half-applied; the allowed extremes render finite."""
import math
import re

import numpy as np
import pytest

from atmos.camera import MAX_FAR_NEAR, MIN_NEAR, Camera
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.render_core import CapturePass
from atmos.runner import build_app

BAD_FIELDS = [  # field, value, words the message must hold
    ("near", 0.0, ["Camera.near", ">= 0.0001"]),
    ("near", -1.0, ["Camera.near", ">= 0.0001"]),
    ("near", 1e-9, ["Camera.near", ">= 0.0001"]),
    ("far", math.inf, ["Camera.far", "finite"]),
    ("fov_y", 0.0, ["Camera.fov_y", "radians in (0, pi)"]),
    ("fov_y", 60, ["Camera.fov_y", "degrees? math.radians(60) = 1.047"]),
    ("fov_y", math.pi, ["Camera.fov_y", "(0, pi)"]),
    ("yaw", math.nan, ["Camera.yaw", "finite"]),
    ("roll", math.inf, ["Camera.roll", "finite"]),
    ("pitch", 2.0, ["Camera.pitch", "<= 1.57"]),
    ("pitch", "up", ["Camera.pitch", "'up'"]),
    ("position", (0.0, math.nan, 0.0), ["Camera.position", "3 finite numbers"]),
    ("position", (1.0, 2.0), ["Camera.position", "3 finite numbers"]),
]


@pytest.mark.parametrize("field, value, words", BAD_FIELDS, ids=[f"{f}={v!r}" for f, v, _ in BAD_FIELDS])
def test_a_bad_field_fails_where_it_is_set_and_changes_nothing(field, value, words):
    cam = Camera()
    before = np.copy(getattr(cam, field))
    with pytest.raises(ValueError) as error:
        setattr(cam, field, value)
    assert all(w in str(error.value) for w in words), str(error.value)
    np.testing.assert_array_equal(getattr(cam, field), before)
    with pytest.raises(ValueError, match=f"Camera.{field}"):
        Camera(**{field: value})


@pytest.mark.parametrize("near, far, words", [(5.0, 5.0, "greater than Camera.near"),
                                              (10.0, 1.0, "greater than Camera.near"),
                                              (1e-4, 1e12, re.escape(f"at most {MAX_FAR_NEAR:g}"))])
def test_planes_that_do_not_fit_together(near, far, words):
    with pytest.raises(ValueError, match=words):
        Camera(near=near, far=far)
    cam = Camera()
    cam.near, cam.far = 500.0, 1e5          # passes through near > far: fine until a frame is drawn
    cam.check()
    cam.near, cam.far = near, far
    with pytest.raises(ValueError, match=words):
        cam.check()


def test_a_bad_camera_fails_before_the_frame_renders(gpu, ctx):
    from atmos.app import App
    from atmos.defaults import DefaultPlugins
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False))
    try:
        app.run_frames(1)
        cam = app.resource(Camera)
        cam.far = cam.near
        with pytest.raises(ValueError, match="Camera.far must be greater than Camera.near"):
            app.update(1 / 60)
        cam.far = 100.0
        cam.position[1] = math.nan                               # an in-place edit no setter sees
        with pytest.raises(ValueError, match="Camera.position"):
            app.update(1 / 60)
        cam.position = (0.0, 2.0, 0.0)
        app.update(1 / 60)
    finally:
        app.close()


EXTREMES = {
    "widest": dict(fov_y=math.pi - 1e-6),
    "narrowest": dict(fov_y=1e-6),
    "planes": dict(near=MIN_NEAR, far=MIN_NEAR * MAX_FAR_NEAR),
    "straight_up_rolled": dict(pitch=math.pi / 2, roll=2.0),
    "straight_down_rolled": dict(pitch=-math.pi / 2, roll=-1.0),
    "huge_angles": dict(yaw=1e6, roll=-1e6),
}


@pytest.mark.parametrize("case", sorted(EXTREMES))
def test_allowed_extremes_render_finite(case):
    gpu = create_headless((32, 32))
    capture = CapturePass()
    try:
        app = build_app("sunset", DemoSettings(size=gpu.size, headless=True), gpu, start=False)
        app.graph.add_pass(capture)
        app.run_frames(2, 1 / 30)
        cam = app.resource(Camera)
        for name, value in EXTREMES[case].items():
            setattr(cam, name, value)
        app.render()
        assert gpu.ctx.error == "GL_NO_ERROR"
        assert np.isfinite(capture.color).all() and (capture.color >= 0).all()
        app.close()
    finally:
        gpu.release()
