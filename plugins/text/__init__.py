"""Text over the frame (a HUD): every entity with a :class:`Label` is drawn on the screen after
``present``, rasterised by Pillow's FreeType renderer (its bundled font, or ``TextPlugin(font="x.ttf")``),
so it looks the same in a window and headless::

    score = app.world.create_entity(Label("score 0", x=12, y=10, size=24))
    app.world.component_for_entity(score, Label).text = "score 1"      # re-rasterised once

``anchor`` (ax, ay) in [0, 1] picks the point of the frame and of the label that meet, offset by
(x, y) pixels (y down): (0, 0) top left, (0.5, 0.5) centred, (1, 1) bottom right. With
``TextPlugin(design_height=540)`` sizes and offsets are pixels of a frame that tall, scaled to the
frame's height: the HUD keeps its size relative to the window.
"""
from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

from atmos.checks import check_int, check_num, check_vec
from atmos.graph import FullscreenPass, PassContext
from atmos.plugin import Plugin
from atmos.plugins.text.raster import font as load_font, rasterize
from atmos.render_core import SCREEN
from atmos.gpu.uniforms import bind_textures

CACHE = 256      # rasterised labels kept on the GPU, least recently drawn released first


@dataclass(slots=True)
class Label:
    """``text`` at (``x``, ``y``) pixels from ``anchor`` of the frame, ``size`` pixels tall, in
    ``color`` (display sRGB r, g, b and opacity a, each 0..1)."""
    text: str
    x: float = 0.0
    y: float = 0.0
    size: int = 20
    color: tuple = (1.0, 1.0, 1.0, 1.0)
    anchor: tuple = (0.0, 0.0)

    def __post_init__(self):
        self.check()

    def check(self) -> "Label":
        if not isinstance(self.text, str):
            raise ValueError(f"Label.text must be a str, got {type(self.text).__name__}")
        self.x, self.y = check_num("Label", "x", self.x), check_num("Label", "y", self.y)
        self.size = check_int("Label", "size", self.size, 4, 512)
        self.color = check_vec("Label", "color", self.color, 4, "non-negative")
        if max(self.color) > 1.0:
            raise ValueError(f"Label.color must be 4 numbers in 0..1 (r, g, b, opacity), got {self.color!r}")
        self.anchor = check_vec("Label", "anchor", self.anchor, 2, "non-negative")
        if max(self.anchor) > 1.0:
            raise ValueError(f"Label.anchor must be 2 numbers in 0..1, got {self.anchor!r}")
        return self


def label_origin(label: Label, shape: tuple[int, int], frame: tuple[int, int], scale: float = 1.0) -> tuple[int, int]:
    """Top-left pixel (x, y down) of a label whose bitmap is ``shape`` (h, w) in a ``frame`` (w, h), its
    offset scaled by ``scale``."""
    ax, ay = label.anchor
    return (round(ax * frame[0] - ax * shape[1] + label.x * scale),
            round(ay * frame[1] - ay * shape[0] + label.y * scale))


class TextPass(FullscreenPass):
    name = "text"
    phase = "overlay"
    fragment = "text/label.frag"
    reads = (SCREEN,)                                # blends onto it
    writes = (SCREEN,)

    def __init__(self, plugin):
        super().__init__(plugin)
        self.textures: OrderedDict = OrderedDict()   # (text, size) -> texture

    def setup(self, builder) -> None:
        if self.plugin.labels:
            super().setup(builder)                   # nothing to draw: declares nothing, culled

    def _texture(self, ctx, label: Label, size: int):
        key = (label.text, size)
        texture = self.textures.get(key)
        if texture is None:
            coverage = rasterize(label.text, size, self.plugin.font)
            texture = self.textures[key] = ctx.texture(coverage.shape[::-1], 1, coverage.tobytes(), alignment=1)
            while len(self.textures) > CACHE:
                self.textures.popitem(last=False)[1].release()
        self.textures.move_to_end(key)
        return texture

    def execute(self, frame: PassContext) -> None:
        ctx = frame.gpu.ctx
        frame.resource(SCREEN).use()
        frame.blend_alpha()
        w, h = frame.gpu.size
        scale = h / self.plugin.design_height if self.plugin.design_height else 1.0
        program = self.program
        for label in self.plugin.labels:
            texture = self._texture(ctx, label, min(max(round(label.size * scale), 4), 512))
            x, y = label_origin(label, (texture.height, texture.width), (w, h), scale)
            ctx.viewport = (x, h - y - texture.height, texture.width, texture.height)   # the graph resets it
            bind_textures(program, coverage=texture)
            program["color"].value = label.color
            frame.fullscreen(program)

    def release(self) -> None:
        for texture in self.textures.values():
            texture.release()
        self.textures.clear()


class TextPlugin(Plugin):
    """Draws every :class:`Label` entity over the frame (pass "text", after the frame-time overlay).
    ``font``: a .ttf/.otf file (checked here), or None for Pillow's bundled font. ``design_height``:
    None (labels in frame pixels) or the frame height (pixels) the labels are laid out for; they scale
    with the frame's height."""

    def __init__(self, font: str | None = None, design_height: int | None = None):
        super().__init__()
        if font is not None and not isinstance(font, str):
            raise ValueError(f"TextPlugin.font must be a font file path or None, got {font!r}")
        if font is not None:
            load_font(font, 12)                      # fails now, naming the file, if it is no font
        self.font = font
        self.design_height = None if design_height is None else check_int("TextPlugin", "design_height",
                                                                          design_height, 16, 16384)

    def build(self, app) -> None:
        self.labels: list[Label] = []
        self.text_pass = None
        app.add_system(self.collect, "render", label="collect_labels", before="frame_scheduler")
        if app.graph is not None:
            self.text_pass = app.graph.add_pass(TextPass(self))

    def finish(self, app) -> None:
        if self.text_pass is not None and any(p.name == "overlay" for p in app.graph.passes):
            self.text_pass.after = ("overlay",)      # both blend onto the screen: text on top

    def collect(self, app) -> None:
        self.labels = [label.check() for _, label in app.world.get_component(Label) if label.text]
