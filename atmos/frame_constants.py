"""The frame's constants (``shaders/lib/frame.glsl``): camera, sun, time and frame size packed in
std140 into one uniform buffer, written once per frame and bound at uniform-buffer binding
:data:`FRAME_BINDING` for every program (:meth:`atmos.graph.RenderGraph.execute` does it).

A program that includes ``lib/frame.glsl`` reads these from the block; the per-program writers of
:mod:`atmos.scene_uniforms` skip it. To draw such a program outside a graph frame, call
:func:`bind_frame` with the camera and sun to draw with first.
"""
from __future__ import annotations

import numpy as np

from atmos.camera import Camera, camera_matrices
from atmos.gpu.shaders import FRAME_BINDING, FRAME_BLOCK   # (the compiler check keeps binding 0 for it)
from atmos.gpu.uniforms import std140_mat3
from atmos.lighting import Sun

__all__ = ["FRAME_BINDING", "FRAME_BLOCK", "FRAME_SIZE", "LAYOUT", "FrameConstants", "bind_frame",
           "frame_constants", "pack_frame", "view_frame"]
FRAME_SIZE = 256
# member -> (byte offset, float32 count) under std140: a mat4 is 4 vec4 columns, a mat3 3 vec4
# columns (each padded to 16 bytes), a vec3 takes 12 bytes of a 16-byte slot whose last 4 the next
# float may fill, a vec2 aligns to 8.
LAYOUT = {"view_proj": (0, 16), "inv_view_proj": (64, 16), "view_basis": (128, 12), "camera_pos": (176, 3),
          "near": (188, 1), "sun_dir": (192, 3), "far": (204, 1), "sun_color": (208, 3), "time": (220, 1),
          "sky_ambient": (224, 3), "frame_index": (236, 1), "jitter": (240, 2), "resolution": (248, 2)}


def pack_frame(camera: Camera, sun: Sun, size, time: float = 0.0, frame_index: int = 0,
               jitter=(0.0, 0.0)) -> bytes:
    """The block's bytes for ``camera`` and ``sun`` at frame ``size`` (w, h): float32 values, the
    matrices column-major as :func:`atmos.camera.gl_matrix` writes them, ``frame_index`` a uint32."""
    matrices = camera_matrices(camera, size[0] / size[1])
    f = np.zeros(FRAME_SIZE // 4, np.float32)
    f[0:16] = np.frombuffer(matrices.gl("view_proj"), np.float32)
    f[16:32] = np.frombuffer(matrices.gl("inv_view_proj"), np.float32)
    f[32:44] = std140_mat3(matrices.gl("view_basis"))
    f[44:47] = matrices.camera_pos
    f[47] = camera.near
    f[48:51] = sun.direction
    f[51] = camera.far
    f[52:55] = sun.color
    f[55] = time
    f[56:59] = sun.ambient
    f[60:62] = jitter
    f[62:64] = size
    f.view(np.uint32)[59] = int(frame_index) & 0xFFFFFFFF
    return f.tobytes()


class FrameConstants:
    """One GpuContext's frame block buffer. :meth:`write` uploads (when changed) and binds it;
    :meth:`begin` / :meth:`end` bracket a graph frame, so a graph run inside another's pass gives
    the outer frame its block back when it ends."""

    def __init__(self, gpu):
        self.buffer = gpu.track(gpu.ctx.buffer(reserve=FRAME_SIZE))
        self.data = b""
        self._outer: list[bytes] = []

    def write(self, data: bytes) -> None:
        """Upload ``data`` unless the buffer holds it already; bind the buffer at FRAME_BINDING."""
        if data != self.data:
            self.buffer.write(data)
            self.data = data
        self.buffer.bind_to_uniform_block(FRAME_BINDING)

    def begin(self, data: bytes) -> None:
        """A frame starts: :meth:`write` ``data``, remembering what an enclosing frame had."""
        self._outer.append(self.data)
        self.write(data)

    def end(self) -> None:
        """The frame started last ends: inside another frame, that frame's data again."""
        outer = self._outer.pop()
        if self._outer and outer:
            self.write(outer)


def frame_constants(gpu) -> FrameConstants:
    """The :class:`FrameConstants` of GpuContext ``gpu`` (made on first use, released with it)."""
    made = getattr(gpu, "_frame_constants", None)
    if made is None:
        made = gpu._frame_constants = FrameConstants(gpu)
    return made


def view_frame(view) -> bytes | None:
    """:func:`pack_frame` of an :class:`atmos.SceneView`: its camera, sun, size, time and clock frame
    (None for a view without a camera, sun and size: nothing to write)."""
    if not (hasattr(view, "camera") and hasattr(view, "sun") and hasattr(view, "size")):
        return None
    clock = getattr(view, "clock", None)
    return pack_frame(view.camera, view.sun, view.size, getattr(view, "time", 0.0),
                      clock.frame if clock is not None else 0, getattr(view, "jitter", (0.0, 0.0)))


def bind_frame(gpu, camera: Camera | None = None, sun: Sun | None = None, size=None, time: float = 0.0,
               frame_index: int = 0, jitter=(0.0, 0.0)) -> None:
    """Fill and bind the frame block for a draw outside a graph frame (a tool, a test): ``camera``
    and ``sun`` (defaults ``Camera()``, ``Sun()``) at ``size`` (default: the context's frame size)."""
    gpu.make_current()
    frame_constants(gpu).write(pack_frame(camera or Camera(), sun or Sun(), size or gpu.size, time,
                                          frame_index, jitter))
