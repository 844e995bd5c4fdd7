"""Anti-aliasing of the frame's edges (meshes, terrain, the horizon): ``AntialiasPlugin(settings=None,
**fields)`` with :class:`AntialiasSettings`, in one of two modes (or ``"none"``), both on the HDR
colour just before ``present``:

- ``"fxaa"`` (FXAA, Lottes 2009): the stair steps of every opaque edge blurred along the edge, nothing
  else touched; the pass copies ``color`` and writes the filtered image back into it, one compute
  invocation per pixel (``shaders/antialias/fxaa.comp``).
- ``"taa"`` (temporal, :mod:`.temporal`): the geometry drawn a sub-pixel off each frame and the frames
  blended through reprojection, so a still view converges to a supersampled one and the shading's
  own aliasing (a checkerboard into the distance) goes too.

float64 references: :mod:`.reference`."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, bool_field, choice_field, num_field
from atmos.graph import ComputePass, PassBuilder, PassContext, TextureDesc
from atmos.gpu.uniforms import write_uniforms
from atmos.plugin import Plugin
from atmos.render_core import COLOR, motion_targets
from atmos.scene_view import FrameJitter
from atmos.plugins.antialias.temporal import TemporalAAPass, jitter_offset, jitter_system

SOURCE = "antialias_source"      # the copy of the frame's colour the filter reads


@dataclass(frozen=True)
class AntialiasSettings(CheckedSettings):
    """The mode and its constants (all live)."""
    mode: str = choice_field("fxaa", ("fxaa", "taa", "none"), "fxaa: a filter along the edges of each frame; taa: "
                             "the geometry jittered every frame and the frames blended through reprojection; "
                             "none: no pass")
    motion: bool = bool_field(True, "taa: follow moving meshes by their own motion since the last frame (a "
                              "motion target the meshes draw; off: every point is reprojected by the camera's "
                              "motion alone, and a moving mesh's history trails behind it until the clamp cuts it)")
    history: float = num_field(0.1, 0.0, 1.0, "taa: the newest frame's least weight (a running mean of a still "
                               "view until 1 / (n + 1) falls to it; smaller: smoother and slower to follow)",
                               lo_open=True)
    span_max: float = num_field(8.0, 1.0, 16.0, "fxaa: pixels: the longest blur along an edge")
    reduce_mul: float = num_field(1 / 8, 0.0, 1.0, "fxaa: how much a bright neighbourhood shortens the blur")
    reduce_min: float = num_field(1 / 128, 1e-4, 1.0, "fxaa: the least shortening (keeps flat areas sharp)")


class AntialiasPass(ComputePass):
    """Reads and writes ``color`` in phase ``present`` (so before the tone mapping reads it)."""
    name = "antialias"
    phase = "present"
    compute = "antialias/fxaa.comp"

    def setup_key(self) -> tuple:
        return (self.plugin.settings.mode, self.plugin.gpu.size)

    def setup(self, builder: PassBuilder) -> None:
        if self.plugin.settings.mode != "fxaa":
            return
        w, h = self.plugin.gpu.size
        builder.create(SOURCE, TextureDesc((w, h), components=4, dtype="f2"))
        builder.read(COLOR, access="attachment")      # copied as a framebuffer
        builder.write(COLOR, access="storage")

    def execute(self, frame: PassContext) -> None:
        s, p = self.plugin.settings, self.program
        frame.gpu.ctx.copy_framebuffer(frame.resource(SOURCE), frame.framebuffer(color=[COLOR]))
        write_uniforms(p, span_max=s.span_max, reduce_mul=s.reduce_mul, reduce_min=s.reduce_min)
        color = frame.image(COLOR)
        frame.dispatch(p, self.groups(color.size), textures={"source": SOURCE}, images={"color_image": color})


class AntialiasPlugin(Plugin):
    """Anti-aliases the frame (pass "antialias" in mode fxaa, "temporal_aa" and the geometry's jitter in
    mode taa); ``configure(**changes)`` changes the mode and the constants live."""

    settings_class = AntialiasSettings
    taa = None

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("AntialiasPlugin needs an App with a GPU context (App(gpu))")
        self.gpu = app.gpu
        self.motion = motion_targets(app)
        app.graph.add_pass(AntialiasPass(self))
        self.taa = app.graph.add_pass(TemporalAAPass(self))
        self.motion.readers[self.taa.name] = self.taa.wants_motion
        app.add_system(jitter_system(self, app.init_resource(FrameJitter)), "update", label="antialias_jitter")

    def cleanup(self, app) -> None:
        motion = getattr(self, "motion", None)
        if motion is not None and self.taa is not None:
            motion.readers.pop(self.taa.name, None)


__all__ = ["AntialiasPass", "AntialiasPlugin", "AntialiasSettings", "TemporalAAPass", "jitter_offset"]
