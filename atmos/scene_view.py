"""SceneView: what every render pass sees of the scene this frame (``frame.view``)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.camera import Camera
from atmos.clock import FixedClock
from atmos.lighting import GroundSurface, Sun


@dataclass
class FrameJitter:
    """App resource: this frame's sub-pixel offset (x, y) in pixels of the scene's rasterised geometry,
    set each frame by a temporal antialiasing plugin (:mod:`atmos.plugins.antialias.temporal`); it reaches the
    frame block's ``jitter`` (``lib/frame.glsl`` ``jitter_clip``). Without the resource: (0, 0)."""
    pixels: tuple = (0.0, 0.0)


@dataclass(frozen=True, slots=True)
class SceneView:
    """This frame's camera, sun, clock and frame size, and the ground's surface (None where no plugin
    draws one), built by the App before the graph runs.

    A scene without a ``Camera`` or ``Sun`` resource gets the defaults (``Camera()``,
    ``Sun()``). Passes read the scene through it, never through the App; what a pass needs of the
    simulation comes as an imported graph resource (for clouds: ``"cloud_sets"``). ``jitter``: the
    geometry's sub-pixel offset this frame (:class:`FrameJitter`).
    """
    camera: Camera
    sun: Sun
    clock: FixedClock
    size: tuple[int, int]
    ground: GroundSurface | None = None
    jitter: tuple = (0.0, 0.0)

    @property
    def aspect(self) -> float:
        """Width / height of the frame."""
        return self.size[0] / self.size[1]

    @property
    def time(self) -> float:
        """Seconds of frame time so far (``clock.frame_time``): what animated effects follow."""
        return self.clock.frame_time

    @classmethod
    def of(cls, app) -> "SceneView":
        """The view of ``app`` now; the camera is checked (:meth:`Camera.check`) so a bad one fails here,
        before the frame renders, naming the field."""
        jitter = app.get_resource(FrameJitter)
        return cls((app.get_resource(Camera) or _DEFAULT_CAMERA).check(), app.get_resource(Sun) or _DEFAULT_SUN, app.clock,
                   app.gpu.size, app.get_resource(GroundSurface), (0.0, 0.0) if jitter is None else jitter.pixels)


_DEFAULT_CAMERA = Camera()
_DEFAULT_SUN = Sun()
