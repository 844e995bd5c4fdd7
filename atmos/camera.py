"""The perspective camera resource and its matrices (scene data: the uniforms are atmos.scene_uniforms')."""
from __future__ import annotations

import math
import operator
from dataclasses import dataclass, field

import numpy as np

from atmos.checks import check_num, check_vec
from atmos.orientation import angles, basis


#: The smallest ``near`` (m): rasterised geometry keeps a depth below 1 out to about 1.6e7 × near
#: (24-bit depth), 1.6 km at this limit; a smaller near loses the terrain behind a few centimetres.
MIN_NEAR = 1e-4
#: The largest far / near: view rays and distances from depth stay exact in float32 up to here.
MAX_FAR_NEAR = 1e15


@dataclass(slots=True)
class Camera:
    """World-space camera (y up), angles in radians (:mod:`atmos.orientation`): yaw 0 looks along −z,
    pitch > 0 looks up (−π/2 … π/2), roll > 0 banks right. ``fov_y``: vertical field of view in
    radians, in (0, π); ``near``, ``far``: the clip planes in metres, ``MIN_NEAR <= near < far``,
    far / near at most ``MAX_FAR_NEAR``.

    Every field is checked when it is set (a ValueError names the field, the value and what is
    allowed); near < far is checked at construction and by :meth:`check`, which the App runs before
    each frame (so ``cam.near, cam.far = 500, 1e5`` may pass through near > far in between).
    """
    position: np.ndarray = field(default_factory=lambda: np.array([0.0, 2.0, 8.0]))
    yaw: float = 0.0
    pitch: float = 0.0
    roll: float = 0.0
    fov_y: float = math.radians(60.0)
    near: float = 0.1
    far: float = 2000.0

    def __setattr__(self, name: str, value) -> None:
        object.__setattr__(self, name, _check_field(name, value))

    def __post_init__(self):
        self.check()

    def check(self) -> "Camera":
        """Raise a ValueError unless the fields fit together (near < far, far / near, a finite
        position even after in-place edits); returns the camera."""
        p = self.position             # the angles, fov and distances are floats checked when set
        if type(p) is not np.ndarray or p.shape != (3,) or not math.isfinite(p[0] + p[1] + p[2]):
            _check_field("position", p)   # an in-place edit: the error (or a sum past the float range)
        if not self.far > self.near:
            raise ValueError(f"Camera.far must be greater than Camera.near, got near={self.near!r}, far={self.far!r}")
        if self.far / self.near > MAX_FAR_NEAR:
            raise ValueError(f"Camera.far / Camera.near must be at most {MAX_FAR_NEAR:g} (depth and view rays lose "
                             f"precision beyond), got near={self.near!r}, far={self.far!r}: raise near")
        return self

    def basis(self) -> np.ndarray:
        """3×3 matrix with columns right, up, forward (:func:`atmos.orientation.basis`)."""
        return basis(self.yaw, self.pitch, self.roll)

    def forward(self) -> np.ndarray:
        return self.basis()[:, 2]

    def right(self) -> np.ndarray:
        return self.basis()[:, 0]

    def up(self) -> np.ndarray:
        return self.basis()[:, 1]

    def look_at(self, target, up=None) -> "Camera":
        """Turn toward ``target`` (a point); ``up`` (a direction) sets the roll, else roll is kept."""
        d = np.asarray(target, float) - self.position
        if not (d.shape == (3,) and np.isfinite(d).all() and d.any()):
            raise ValueError(f"look_at needs a finite target other than the camera's position, got {target!r}")
        yaw, pitch, roll = angles(d, up)
        self.yaw, self.pitch = yaw, pitch
        if up is not None:
            self.roll = roll
        return self

    def orbit(self, target, radius: float, height: float, angle: float) -> "Camera":
        """Stand on a circle of ``radius`` around ``target`` at ``height``, at ``angle`` (radians),
        looking at ``target``: the scripted camera of headless demo runs."""
        self.position = np.array([target[0] + radius * math.sin(angle), height, target[2] + radius * math.cos(angle)])
        return self.look_at(target)

    def view(self) -> np.ndarray:
        """World → view matrix (view space: x right, y up, z backward)."""
        r, u, f = self.basis().T
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


def _check_field(name: str, value):
    """The value of Camera field ``name`` as stored, or a ValueError naming it and what is allowed."""
    if name == "position":
        return np.array(check_vec("Camera", "position", value, 3), np.float64)
    if name in ("yaw", "roll"):
        return check_num("Camera", name, value)
    if name == "pitch":
        return check_num("Camera", name, value, -math.pi / 2, math.pi / 2)
    if name == "fov_y":
        v = check_num("Camera", name, value)
        if not 0.0 < v < math.pi:
            hint = f" (degrees? math.radians({v:g}) = {math.radians(v):.4g})" if math.pi <= v < 180 else ""
            raise ValueError(f"Camera.fov_y must be radians in (0, pi), got {value!r}{hint}")
        return v
    if name == "near":
        return check_num("Camera", name, value, MIN_NEAR)
    if name == "far":
        return check_num("Camera", name, value, MIN_NEAR, lo_open=True)
    raise AttributeError(f"Camera has no field {name!r}")


def gl_matrix(m: np.ndarray) -> bytes:
    """A 4×4 (or 3×3) numpy matrix as the column-major float32 bytes a GLSL mat4 (mat3) uniform expects."""
    return np.asarray(m, np.float32).T.tobytes()


def view_basis(camera: Camera, aspect: float) -> np.ndarray:
    """3×3 matrix M with ``M @ (ndc_x, ndc_y, 1)`` along the view ray through that point of the screen:
    columns right·tan(fov_x/2), up·tan(fov_y/2), forward (so the ray's forward component is 1: the
    point at view depth z is ``camera.position + z · ray``). The same rays as unprojecting with the
    inverse view-projection, but independent of the near and far planes (unprojecting in float32
    breaks down at far/near ~ 1e11). The ``view_basis`` uniform of ``lib/view_ray.glsl``."""
    r, u, f = camera.basis().T
    ty = math.tan(0.5 * camera.fov_y)
    return np.column_stack([r * ty * max(aspect, 1e-6), u * ty, f])


class CameraMatrices:
    """What one camera state and aspect give a frame, computed once (:func:`camera_matrices`):
    ``view``, ``projection``, ``view_proj`` and ``view_basis`` (:func:`view_basis`) as read-only
    float64 arrays, exactly what the Camera's methods return; :meth:`gl` their uniform bytes."""
    __slots__ = ("view", "projection", "view_proj", "view_basis", "camera_pos", "_gl")

    def __init__(self, camera: Camera, aspect: float):
        self.view, self.projection = camera.view(), camera.projection(aspect)
        self.view_proj = self.projection @ self.view
        self.view_basis = view_basis(camera, aspect)
        for m in (self.view, self.projection, self.view_proj, self.view_basis):
            m.flags.writeable = False
        self.camera_pos = tuple(map(float, camera.position))
        self._gl: dict[str, bytes] = {}

    def gl(self, name: str) -> bytes:
        """The column-major float32 bytes of uniform ``view_proj``, ``inv_view_proj`` or ``view_basis``."""
        data = self._gl.get(name)
        if data is None:
            if name == "view_proj":
                data = gl_matrix(self.view_proj)
            elif name == "inv_view_proj":
                data = gl_matrix(np.linalg.inv(self.view_proj))
            elif name == "view_basis":
                data = gl_matrix(self.view_basis)
            else:
                raise KeyError(f"CameraMatrices.gl: no uniform {name!r} (view_proj, inv_view_proj, view_basis)")
            self._gl[name] = data
        return data


_MATRICES: dict = {}          # camera state + aspect -> CameraMatrices, a few kept
_STATE = operator.attrgetter(*(f for f in Camera.__dataclass_fields__ if f != "position"))


def camera_matrices(camera: Camera, aspect: float) -> CameraMatrices:
    """The :class:`CameraMatrices` of ``camera`` as it is now, at ``aspect``: computed on the first
    ask for this state (every field, the position by value) and shared by every pass of the frame."""
    key = (float(aspect), camera.position.tobytes(), *_STATE(camera))
    matrices = _MATRICES.get(key)
    if matrices is None:
        if len(_MATRICES) >= 8:
            _MATRICES.clear()
        matrices = _MATRICES[key] = CameraMatrices(camera, aspect)
    return matrices
