"""Compositing over a frame the game drew itself: atmos adds sky, clouds, shadows and fog around and
over it.

The game renders its scene into a colour texture and a depth texture of its own (any GL code, on the
App's context), and gives them to ``HostFramePlugin(color, depth)`` (textures, or zero-argument
callables returning the current ones, e.g. after a resize). Each frame, first thing (phase
``clear``), they are copied into atmos's ``color`` and ``depth``; the skies then draw only where the
depth is still 1 (nothing drawn: each sky pixel tests its depth), and clouds,
shadows and fog use the game's depth like the terrain's. The colour is taken as linear radiance
(``srgb=True``: decoded from sRGB first), then tone-mapped with the rest by ``present``.

A game that draws with atmos's own passes does not need this: a pass in phase ``opaque`` that
writes ``color`` and ``depth`` lands before clouds, shadows and fog.
"""
from __future__ import annotations

import moderngl
import numpy as np

from atmos.checks import check_bool
from atmos.composition import composition
from atmos.graph import FullscreenPass, PassContext
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_textures

HOST_COLOR = "host_color"
HOST_DEPTH = "host_depth"


def host_frame_reference(color, depth, srgb: bool) -> tuple[np.ndarray, np.ndarray]:
    """float64 (color RGBA, depth) atmos starts the frame with, from the game's (h, w, ≥3) colour in
    [0, 1] (or linear) and (h, w) depth: what ``core/host_frame.frag`` computes."""
    rgb = np.asarray(color, np.float64)[..., :3]
    if srgb:
        rgb = np.where(rgb < 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    depth = np.asarray(depth, np.float64)
    return np.dstack([rgb, (depth < 1.0).astype(np.float64)]), depth


def _texture(source, what: str, depth: bool):
    texture = source() if callable(source) else source
    if not isinstance(texture, moderngl.Texture) or (texture.depth != depth):
        kind = "a depth texture (ctx.depth_texture)" if depth else "a colour texture (ctx.texture)"
        raise ValueError(f"HostFramePlugin {what} must be {kind} or a callable returning one, got {texture!r}")
    return texture


class HostFramePass(FullscreenPass):
    """Copies the game's colour and depth into ``color`` and ``depth`` (phase clear, after the clear)."""
    name = "host_frame"
    phase = "clear"
    fragment = "core/host_frame.frag"
    reads = (COLOR, DEPTH, HOST_COLOR, HOST_DEPTH)
    writes = (COLOR, DEPTH)

    def defines(self) -> dict:
        return {"SRGB": int(self.plugin.srgb)}

    def execute(self, frame: PassContext) -> None:
        color = _texture(frame.resource(HOST_COLOR), "color", depth=False)
        depth = _texture(frame.resource(HOST_DEPTH), "depth", depth=True)
        frame.framebuffer(color=[COLOR], depth=DEPTH).use()
        ctx = frame.gpu.ctx
        ctx.enable(moderngl.DEPTH_TEST)                  # depth writes need the test on
        ctx.depth_func = "1"                             # always
        compare = depth.compare_func
        depth.compare_func = ""                          # sampled as values; the game's setting comes back
        try:
            bind_textures(self.program, host_color=color, host_depth=depth)
            frame.fullscreen(self.program)
        finally:
            depth.compare_func = compare


class HostFramePlugin(Plugin):
    """``HostFramePlugin(color, depth, srgb=False)``: start every frame from the game's own colour and
    depth textures (see the module docstring)."""

    def __init__(self, color, depth, srgb: bool = False):
        super().__init__()
        for what, source, is_depth in (("color", color, False), ("depth", depth, True)):
            if not callable(source):
                _texture(source, what, is_depth)
        self.color, self.depth = color, depth
        self.srgb = check_bool("HostFramePlugin", "srgb", srgb)

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("HostFramePlugin needs an App with a GPU context (App(gpu))")
        app.graph.import_resource(HOST_COLOR, self.color)
        app.graph.import_resource(HOST_DEPTH, self.depth)
        app.graph.add_pass(HostFramePass(self))
        self.composition = composition(app)
        self.composition.backgrounds.add(HostFramePass.name)    # the copy writes every pixel of the colour

    def cleanup(self, app) -> None:
        comp = getattr(self, "composition", None)
        if comp is not None:
            comp.backgrounds.discard(HostFramePass.name)
