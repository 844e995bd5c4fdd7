"""Temporal anti-aliasing (``AntialiasSettings.mode = "taa"``): the scene's rasterised geometry moves
by a sub-pixel offset each frame (:func:`jitter_offset`, through :class:`atmos.scene_view.FrameJitter`
and ``lib/frame.glsl`` ``jitter_clip``) and pass "temporal_aa" (phase present, before the exposure,
bloom and tone map read the colour) blends each frame over its reprojected history
(``shaders/antialias/taa_resolve.comp``), then writes the result back into ``color``; the result is
kept (two rgba16f textures, one the last output, read by Catmull-Rom) for the next frame. A still view
converges to the mean of its jittered frames (a running mean while 1 / (n + 1) > ``history``); a moving
one keeps edges whole through the neighbourhood clamp, its newest frame weighing more the farther each
point moved. Moving meshes are followed by their own motion (``AntialiasSettings.motion``: the
motion target of :class:`atmos.render_core.MotionTargets`), not only the camera's. float64 twin:
:mod:`.reference` (``taa_resolve``)."""
from __future__ import annotations

import struct

from atmos.camera import camera_matrices
from atmos.graph import ComputePass, PassBuilder, PassContext
from atmos.gpu.uniforms import write_block
from atmos.render_core import COLOR, DEPTH, MOTION
from atmos.scene_view import FrameJitter

TAA_BINDING = 1                 # taa_resolve.comp's TemporalAA block
JITTER_SAMPLES = 8              # sub-pixel positions before the pattern repeats (Halton 2, 3)
MOTION_DEFINES = {"MOTION": 1}  # taa_resolve.comp's variant that reads the meshes' motion target


def halton(n: int, base: int) -> float:
    """The n-th (from 1) point of the van der Corput sequence in ``base``, in (0, 1)."""
    f, r, n = 1.0, 0.0, int(n)
    while n > 0:
        f /= base
        r += f * (n % base)
        n //= base
    return r


def taa_block(prev_view_proj: bytes, weight: float, has_history: bool) -> bytes:
    """taa_resolve.comp's TemporalAA block (std140): the previous view_proj's column-major float32 bytes
    (:meth:`atmos.camera.CameraMatrices.gl`), the newest frame's weight, whether there is a history."""
    return prev_view_proj + struct.pack("<fi8x", weight, has_history)


def jitter_offset(frame_index: int, samples: int = JITTER_SAMPLES) -> tuple[float, float]:
    """The geometry's offset in pixels in frame ``frame_index``: Halton (2, 3) point (n mod ``samples``) + 1,
    centred on the pixel: each coordinate in (-1/2, 1/2), the points filling the pixel evenly."""
    n = int(frame_index) % int(samples) + 1
    return halton(n, 2) - 0.5, halton(n, 3) - 0.5


JITTERS = tuple(jitter_offset(n) for n in range(JITTER_SAMPLES))     # one cycle, frame n takes n mod 8


class TemporalAAPass(ComputePass):
    """Pass "temporal_aa": resolve ``color`` over the history into the next history, then copy that into
    ``color``."""
    name = "temporal_aa"
    phase = "present"

    def __init__(self, plugin):
        super().__init__(plugin)
        self._textures, self._current, self._prev, self.frames, self.weight = None, 0, None, 0, None
        self._size = self._groups = None

    def wants_motion(self) -> bool:
        """Whether this pass reads the moving geometry's motion (the App's MotionTargets asks)."""
        s = self.plugin.settings
        return s.mode == "taa" and s.motion

    def setup_key(self) -> tuple:
        return (self.plugin.settings.mode, self.plugin.motion.wanted)

    def setup(self, builder: PassBuilder) -> None:
        if self.plugin.settings.mode != "taa":
            return
        builder.read(COLOR)
        builder.read(DEPTH)
        if self.plugin.motion.wanted:
            builder.read(MOTION)
        builder.write(COLOR, access="storage")

    def prepare(self, gpu) -> None:
        super().prepare(gpu)
        self.resolve_program = gpu.program(compute_shader="antialias/taa_resolve.comp")
        self.copy_program = gpu.program(compute_shader="antialias/taa_copy.comp")

    def release(self) -> None:
        """Free the history (the next frame starts a new one)."""
        for tex in self._textures or ():
            tex.release()
        self._textures, self._prev, self.frames, self._size = None, None, 0, None

    def execute(self, frame: PassContext) -> None:
        view = frame.view
        matrices = camera_matrices(view.camera, view.aspect)
        size = view.size
        if self._size != size:
            self.release()
            self._textures = []
            for _ in range(2):
                self._textures.append(frame.gpu.track(frame.gpu.ctx.texture(size, 4, dtype="f2")))
            self._size, self._groups = size, self.groups(size)
        prev = matrices if self._prev is None else self._prev
        weight = max(1.0 / (self.frames + 1), self.plugin.settings.history)
        moving = frame.declares(MOTION)
        p = (frame.gpu.program(compute_shader="antialias/taa_resolve.comp", defines=MOTION_DEFINES) if moving
             else self.resolve_program)               # the variant only a scene with moving meshes compiles
        groups = self._groups
        write_block(p, "TemporalAA", TAA_BINDING, taa_block(prev.gl("view_proj"), weight, self.frames > 0))
        history, out = self._textures[self._current], self._textures[1 - self._current]
        textures = {"color_in": COLOR, "depth_in": DEPTH, "history": history}
        if moving:
            textures["motion_in"] = MOTION
        frame.dispatch(p, groups, textures=textures, images={"resolved": out})
        frame.dispatch(self.copy_program, groups, textures={"resolved_in": out}, images={"color_image": COLOR})
        self._current, self._prev = 1 - self._current, matrices
        self.frames += 1
        self.weight = weight                 # the newest frame's weight this frame (tests, tools)


def jitter_system(plugin, jitter: FrameJitter):
    """The system that sets ``jitter`` (the App's :class:`FrameJitter`) each frame: the Halton offset
    while ``mode`` is "taa", else (0, 0) (and the history is let go)."""
    def set_jitter(app) -> None:
        if plugin.settings.mode == "taa":
            jitter.pixels = JITTERS[app.clock.frame % JITTER_SAMPLES]
        elif jitter.pixels != (0.0, 0.0) or plugin.taa.frames:
            jitter.pixels = (0.0, 0.0)
            plugin.taa.release()
    return set_jitter
