"""Anti-aliasing of the frame's edges (meshes, terrain, the horizon): FXAA (Lottes 2009) on the HDR
colour just before ``present``, so the stair steps of every opaque edge are blurred along the edge
and nothing else is touched: ``AntialiasPlugin(settings=None, **fields)`` with :class:`AntialiasSettings`.
The pass copies ``color`` and draws the filtered image back over it (``shaders/antialias/fxaa.frag``;
float64 reference: :mod:`.reference`)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, num_field
from atmos.graph import FullscreenPass, PassBuilder, PassContext, TextureDesc
from atmos.gpu.uniforms import bind_textures, write_uniforms
from atmos.plugin import Plugin
from atmos.render_core import COLOR

SOURCE = "antialias_source"      # the copy of the frame's colour the filter reads


@dataclass(frozen=True)
class AntialiasSettings(CheckedSettings):
    """FXAA's three constants (all live)."""
    span_max: float = num_field(8.0, 1.0, 16.0, "pixels: the longest blur along an edge")
    reduce_mul: float = num_field(1 / 8, 0.0, 1.0, "how much a bright neighbourhood shortens the blur")
    reduce_min: float = num_field(1 / 128, 1e-4, 1.0, "the least shortening (keeps flat areas sharp)")


class AntialiasPass(FullscreenPass):
    """Reads and writes ``color`` in phase ``present`` (so before the tone mapping reads it)."""
    name = "antialias"
    phase = "present"
    fragment = "antialias/fxaa.frag"

    def setup(self, builder: PassBuilder) -> None:
        w, h = self.plugin.gpu.size
        builder.create(SOURCE, TextureDesc((w, h), components=4, dtype="f2"))
        builder.read(COLOR)
        builder.write(COLOR)

    def execute(self, frame: PassContext) -> None:
        s, p = self.plugin.settings, self.program
        frame.gpu.ctx.copy_framebuffer(frame.resource(SOURCE), frame.framebuffer(color=[COLOR]))
        frame.framebuffer(color=[COLOR]).use()
        bind_textures(p, source=frame.resource(SOURCE))
        write_uniforms(p, span_max=s.span_max, reduce_mul=s.reduce_mul, reduce_min=s.reduce_min)
        frame.fullscreen(p)


class AntialiasPlugin(Plugin):
    """Anti-aliases the frame (pass "antialias"); ``configure(**changes)`` changes the constants live."""

    settings_class = AntialiasSettings

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("AntialiasPlugin needs an App with a GPU context (App(gpu))")
        self.gpu = app.gpu
        app.graph.add_pass(AntialiasPass(self))


__all__ = ["AntialiasPass", "AntialiasPlugin", "AntialiasSettings"]
