"""A perspective camera resource and a fly-camera controller driven by the Input resource."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from atmos.plugin import Plugin


@dataclass(slots=True)
class Camera:
    """World-space camera: y is up; yaw 0 looks along −z, pitch > 0 looks up (radians)."""
    position: np.ndarray = field(default_factory=lambda: np.array([0.0, 2.0, 8.0]))
    yaw: float = 0.0
    pitch: float = 0.0
    fov_y: float = math.radians(60.0)
    near: float = 0.1
    far: float = 2000.0

    def forward(self) -> np.ndarray:
        cp = math.cos(self.pitch)
        return np.array([math.sin(self.yaw) * cp, math.sin(self.pitch), -math.cos(self.yaw) * cp])

    def right(self) -> np.ndarray:
        return np.array([math.cos(self.yaw), 0.0, math.sin(self.yaw)])

    def look_at(self, target) -> "Camera":
        d = np.asarray(target, float) - self.position
        self.yaw = math.atan2(d[0], -d[2])
        self.pitch = math.atan2(d[1], math.hypot(d[0], d[2]))
        return self

    def orbit(self, target, radius: float, height: float, angle: float) -> "Camera":
        """Stand on a circle of ``radius`` around ``target`` at ``height``, at ``angle`` (radians),
        looking at ``target``: the scripted camera of headless demo runs."""
        self.position = np.array([target[0] + radius * math.sin(angle), height, target[2] + radius * math.cos(angle)])
        return self.look_at(target)

    def view(self) -> np.ndarray:
        f = self.forward()
        r = self.right()
        u = np.cross(r, f)
        m = np.identity(4)
        m[0, :3], m[1, :3], m[2, :3] = r, u, -f
        m[:3, 3] = -m[:3, :3] @ self.position
        return m

    def projection(self, aspect: float) -> np.ndarray:
        t = 1.0 / math.tan(self.fov_y / 2)
        n, f = self.near, self.far
        m = np.zeros((4, 4))
        m[0, 0], m[1, 1] = t / max(aspect, 1e-6), t
        m[2, 2], m[2, 3] = (f + n) / (n - f), 2 * f * n / (n - f)
        m[3, 2] = -1.0
        return m

    def view_projection(self, aspect: float) -> np.ndarray:
        return self.projection(aspect) @ self.view()


def gl_matrix(m: np.ndarray) -> bytes:
    """A 4×4 numpy matrix as the column-major float32 bytes a GLSL mat4 uniform expects."""
    return np.asarray(m, np.float32).T.tobytes()


@dataclass
class Input:
    """What the window saw this frame: keys held (pyglet key names, lower case) and mouse motion."""
    keys: set = field(default_factory=set)
    pressed: set = field(default_factory=set)   # keys that went down this frame
    mouse_dx: float = 0.0
    mouse_dy: float = 0.0

    def end_frame(self) -> None:
        self.pressed.clear()
        self.mouse_dx = self.mouse_dy = 0.0


def fly_camera(app, speed: float = 20.0, turn: float = 0.004) -> None:
    """System: WASD/QE move, arrow keys or mouse drag turn; shift moves 5× faster."""
    inp: Input | None = app.get_resource(Input)
    cam: Camera | None = app.get_resource(Camera)
    if inp is None or cam is None:
        return
    dt = app.clock.dt
    v = speed * (5.0 if {"lshift", "rshift"} & inp.keys else 1.0) * dt
    move = {"w": cam.forward(), "s": -cam.forward(), "d": cam.right(), "a": -cam.right(),
            "e": np.array([0, 1.0, 0]), "q": np.array([0, -1.0, 0])}
    for key, direction in move.items():
        if key in inp.keys:
            cam.position = cam.position + v * direction
    cam.yaw += inp.mouse_dx * turn + 1.5 * dt * (("right" in inp.keys) - ("left" in inp.keys))
    cam.pitch += inp.mouse_dy * turn + 1.5 * dt * (("up" in inp.keys) - ("down" in inp.keys))
    cam.pitch = float(np.clip(cam.pitch, -1.55, 1.55))


def view_basis(camera: Camera, aspect: float) -> np.ndarray:
    """3×3 matrix M with ``M @ (ndc_x, ndc_y, 1)`` along the view ray through that point of the screen:
    columns right·tan(fov_x/2), up·tan(fov_y/2), forward (so the ray's forward component is 1: the
    point at view depth z is ``camera.position + z · ray``). The same rays as unprojecting with the
    inverse view-projection, but independent of the near and far planes (unprojecting in float32
    breaks down at far/near ~ 1e11). The ``view_basis`` uniform of ``lib/view_ray.glsl``."""
    f, r = camera.forward(), camera.right()
    ty = math.tan(0.5 * camera.fov_y)
    return np.column_stack([r * ty * max(aspect, 1e-6), np.cross(r, f) * ty, f])


def gl_matrix3(m: np.ndarray) -> bytes:
    """A 3×3 numpy matrix as the column-major float32 bytes a GLSL mat3 uniform expects."""
    return np.asarray(m, np.float32).T.tobytes()


def set_camera_uniforms(program, camera: Camera, aspect: float) -> None:
    """Write the camera uniforms ``program`` has (the compiler drops unused ones): ``view_proj``,
    ``inv_view_proj``, ``view_basis`` (:func:`view_basis`), ``camera_pos``, ``near``, ``far``.

    ``view_basis``, ``camera_pos``, ``near`` and ``far`` are what ``lib/view_ray.glsl`` needs for
    view rays and distances from depth at any far/near ratio; prefer them to ``inv_view_proj``."""
    if "view_proj" in program or "inv_view_proj" in program:
        vp = camera.view_projection(aspect)
        if "view_proj" in program:
            program["view_proj"].write(gl_matrix(vp))
        if "inv_view_proj" in program:
            program["inv_view_proj"].write(gl_matrix(np.linalg.inv(vp)))
    if "view_basis" in program:
        program["view_basis"].write(gl_matrix3(view_basis(camera, aspect)))
    for name, value in (("camera_pos", tuple(float(c) for c in camera.position)), ("near", float(camera.near)),
                        ("far", float(camera.far))):
        if name in program:
            program[name].value = value



class CameraPlugin(Plugin):
    """Adds the Camera and Input resources and the fly-camera system (update stage)."""

    def __init__(self, camera: Camera | None = None):
        self.camera = camera or Camera()

    def build(self, app) -> None:
        app.insert_resource(self.camera)
        app.insert_resource(Input())
        app.add_system(fly_camera, "update", label="fly_camera")
        app.add_system(lambda app: app.resource(Input).end_frame(), "last", label="input_end_frame")
