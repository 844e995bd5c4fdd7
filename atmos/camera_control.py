"""The camera resource's plugin and its controllers: the WASD fly camera (the default) and a chase
camera that follows an entity.

``DefaultPlugins()`` includes :class:`FlyCameraPlugin`; ``DefaultPlugins(fly_camera=False)`` leaves it
out, and a game adds ``ChaseCameraPlugin(distance=12)`` and points it at its player with
``chase.target = entity`` (an entity with a :class:`atmos.Transform`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from atmos.camera import Camera
from atmos.checks import CheckedSettings, num_field
from atmos.input import Input
from atmos.keys import key
from atmos.orientation import angles
from atmos.plugin import Plugin
from atmos.transform import Transform


class CameraPlugin(Plugin):
    """Adds the :class:`atmos.Camera` resource (``CameraPlugin(camera)`` to start from your own). What moves
    it is another plugin's: :class:`FlyCameraPlugin` (in DefaultPlugins),
    :class:`ChaseCameraPlugin`, or your own system."""

    def __init__(self, camera: Camera | None = None):
        super().__init__()
        if camera is not None and not isinstance(camera, Camera):
            raise ValueError(f"CameraPlugin takes an atmos Camera or None, got {type(camera).__name__}")
        self.camera = camera or Camera()

    def build(self, app) -> None:
        app.insert_resource(self.camera)


@dataclass(frozen=True)
class FlyCameraSettings(CheckedSettings):
    """The fly camera's speeds (all live)."""
    speed: float = num_field(20.0, 0.0, 1e7, "metres per second (shift: 5×)")
    turn: float = num_field(0.004, 0.0, 1.0, "radians per pixel of mouse drag")


class FlyCameraPlugin(Plugin):
    """WASD/QE move, the arrow keys or a mouse drag turn, shift is 5× faster (update stage, "fly_camera")."""

    settings_class = FlyCameraSettings

    def build(self, app) -> None:
        app.add_system(self.fly, "update", label="fly_camera")

    def fly(self, app) -> None:
        inp, cam = app.get_resource(Input), app.get_resource(Camera)
        if inp is None or cam is None:
            return
        if not inp.keys and not inp.buttons and -math.pi <= cam.yaw <= math.pi and -1.55 <= cam.pitch <= 1.55:
            return                 # nothing held: no move or turn, and the angles are in range already
        s, dt = self.settings, app.clock.dt
        v = s.speed * (5.0 if {key.LSHIFT, key.RSHIFT} & inp.keys else 1.0) * dt
        move = (cam.forward() * inp.axis(key.S, key.W) + cam.right() * inp.axis(key.A, key.D)
                + np.array([0.0, 1.0, 0.0]) * inp.axis(key.Q, key.E))
        cam.position = cam.position + v * move
        drag = bool(inp.buttons)
        cam.yaw = math.remainder(cam.yaw + drag * inp.mouse_dx * s.turn + 1.5 * dt * inp.axis(key.LEFT, key.RIGHT),
                                 2 * math.pi)
        pitch = cam.pitch + drag * inp.mouse_dy * s.turn + 1.5 * dt * inp.axis(key.DOWN, key.UP)
        cam.pitch = float(np.clip(pitch, -1.55, 1.55))


@dataclass(frozen=True)
class ChaseCameraSettings(CheckedSettings):
    """Where the chase camera sits relative to its target and how it follows it (all live)."""
    distance: float = num_field(12.0, 0.0, 1e6, "m behind the target")
    height: float = num_field(3.0, -1e6, 1e6, "m above the target")
    look_ahead: float = num_field(8.0, 0.0, 1e6, "aims at the point this many m in front of the target")
    stiffness: float = num_field(6.0, 0.0, 1e6, "1/s, how fast the camera catches up (exponential; larger "
                                 "is tighter)", lo_open=True)
    bank: float = num_field(0.5, 0.0, 1.0, "how much of the target's roll the camera takes (0 keeps the "
                            "horizon level, 1 rolls with it)")


def chase_point(pose, settings: ChaseCameraSettings) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(eye, look, up) for a target at ``pose`` (a :class:`atmos.transform.Pose`): the eye
    ``distance`` behind it along its heading and ``height`` above, looking at the point ``look_ahead``
    in front of it, with ``bank`` of its roll."""
    b = pose.basis()
    p = np.asarray(pose.position, np.float64)
    heading = np.array([math.sin(pose.yaw), 0.0, -math.cos(pose.yaw)])
    eye = p - settings.distance * heading + np.array([0.0, settings.height, 0.0])
    up = (1.0 - settings.bank) * np.array([0.0, 1.0, 0.0]) + settings.bank * b[:, 1]
    return eye, p + settings.look_ahead * b[:, 2], up


def aim(direction, up) -> tuple[float, float, float]:
    """(yaw, pitch, roll) looking along ``direction`` with ``up`` kept up as far as it goes (level when
    ``up`` is along ``direction`` or ``direction`` is zero: then straight ahead along −z)."""
    if not np.linalg.norm(direction) > 1e-9:
        return 0.0, 0.0, 0.0
    try:
        return angles(direction, up)
    except ValueError:
        return angles(direction)


class ChaseCameraPlugin(Plugin):
    """The camera follows the entity ``target`` (with a Transform) where the target is drawn (its pose
    interpolated by ``clock.alpha``): the eye catches up with ``stiffness``, the aim is exact. Runs in
    the render stage before the frame is drawn ("chase_camera"); snaps to its place on the first
    frame and after :meth:`snap`. A target that is gone leaves the camera where it is."""

    settings_class = ChaseCameraSettings

    def __init__(self, settings: ChaseCameraSettings | None = None, *, target: int | None = None, **fields):
        super().__init__(settings, **fields)
        self.target = target
        self._snap = True

    def snap(self) -> None:
        """Jump to the place behind the target on the next frame (after a reset)."""
        self._snap = True

    def build(self, app) -> None:
        app.add_system(self.follow, "render", label="chase_camera", before="frame_scheduler")

    def follow(self, app) -> None:
        cam = app.get_resource(Camera)
        if cam is None or self.target is None or not app.world.has_entity(self.target):
            return
        transform = app.world.try_component(self.target, Transform)
        if transform is None:
            return
        eye, look, up = chase_point(transform.interpolated(app.clock.alpha), self.settings)
        k = 1.0 if self._snap else 1.0 - math.exp(-self.settings.stiffness * app.clock.dt)
        self._snap = False
        cam.position = cam.position + k * (eye - cam.position)     # the eye lags, the aim does not
        cam.yaw, cam.pitch, cam.roll = aim(look - cam.position, up)
