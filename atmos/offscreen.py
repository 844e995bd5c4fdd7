"""An off-screen layer at 1/``factor`` of the frame size, upsampled onto the frame (GPU Gems 3, ch. 23):
what the cloud renderers draw their clouds into and the light shafts their march.

Filling sprite pixels is most of the cloud pass's cost; at factor 2 the sprites fill a quarter of
the pixels. Three draws: ``core/offscreen_far_depth.frag`` writes each block's farthest scene depth
into the low-res depth target (so a sprite seen through any pixel of the block is drawn); the layer is
drawn into the cleared low-res colour target against it; ``core/offscreen_composite.comp`` (compute)
composites the result onto the frame in place — bilinear inside surfaces, nearest-depth at geometry
edges (``lib/upsample.glsl``). References: :mod:`atmos.offscreen_reference`.
"""
from __future__ import annotations

import math
from functools import lru_cache

import moderngl

from atmos.composition import CLOUD_DISTANCE, distance_desc
from atmos.graph import PassBuilder, PassContext, TextureDesc, work_groups
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import bind_textures, write_uniforms

CLOUD_COLOR = "cloud_color"
CLOUD_DEPTH = "cloud_depth"
CLOUD_LOW_DISTANCE = "cloud_distance_low"   # the low-res "cloud_distance" (atmos.composition)
MAX_DOWNSAMPLE = 8
EDGE = 0.1           # relative view-depth difference between a pixel and a low-res texel that makes an edge


def low_size(size, factor: int) -> tuple[int, int]:
    """The low-res target's size: every pixel of the frame falls in one block."""
    return math.ceil(size[0] / factor), math.ceil(size[1] / factor)


@lru_cache(maxsize=16)
def _low_descs(size, factor: int, storage: bool) -> tuple:
    """The low-res targets' descs (colour, depth, distance) at 1/``factor`` of ``size`` (made once: setups run every frame)."""
    low = low_size(size, factor)
    return (TextureDesc(low, components=4, dtype="f2", filter="nearest", storage=storage),
            TextureDesc(low, depth=True, filter="nearest"), distance_desc(low))


class OffscreenLayer:
    """The low-res targets' declarations and the depth and composite draws of a pass that draws off
    screen (the cloud renderers, the light shafts' march; programs belong to the GpuContext)."""

    def __init__(self, gpu, color: str = CLOUD_COLOR, depth: str = CLOUD_DEPTH, distance: str = CLOUD_LOW_DISTANCE):
        self.color, self.depth = color, depth         # the low-res targets' names (another pass: its own)
        self.distance = distance
        self.gpu = gpu
        self.far_depth = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="core/offscreen_far_depth.frag")

    @staticmethod
    def declare(builder: PassBuilder, size, factor: int, distance: bool = False, color: str = CLOUD_COLOR,
                depth: str = CLOUD_DEPTH, storage: bool = False) -> None:
        """``storage``: a compute pass writes the low-res colour (and distance) as images (then no clear)."""
        color_desc, depth_desc, low_distance = _low_descs(tuple(size), factor, storage)
        builder.create(color, color_desc, access="storage" if storage else None)
        builder.create(depth, depth_desc)
        if distance:
            builder.create(CLOUD_LOW_DISTANCE, low_distance, access="storage" if storage else None)

    def begin(self, frame: PassContext, factor: int, distance: bool = False, clear: bool = True):
        """Write the low-res depth, clear the low-res colour (``clear``; a compute pass that writes every
        texel leaves it); returns the framebuffer to draw sprites into (None without ``clear``)."""
        ctx = frame.gpu.ctx
        frame.framebuffer(depth=self.depth).use()
        bind_textures(self.far_depth, scene_depth=frame.resource(DEPTH))
        write_uniforms(self.far_depth, factor=factor)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "1"                # always: the shader writes the block's farthest depth
        frame.fullscreen(self.far_depth)
        if not clear:
            return None
        fbo = frame.framebuffer(color=[self.color, self.distance] if distance else [self.color],
                                depth=self.depth)
        fbo.depth_mask = False              # clear the colour only: the sprites test the depth just written
        fbo.clear(0.0, 0.0, 0.0, 0.0)
        fbo.use()                           # clear() re-binds the framebuffer bound before it
        return fbo

    def end(self, frame: PassContext, factor: int, near: float, far: float, distance: bool = False,
            medium: bool = False, offset=None, first: bool = False) -> None:
        """Composite the low-res clouds onto "color" in place (premultiplied: layer + (1 − a) · colour,
        as :meth:`PassContext.blend_over` would), and their distance onto the cleared "cloud_distance"
        with the same weights when ``distance`` (``first``: the pass made "cloud_distance", its first
        writer: the distance is stored, nothing cleared); ``medium``: the low-res target holds (in-scattered light,
        transmittance) of a medium instead (L + T · colour, alpha kept). ``offset`` (ox, oy): low-res
        texel (i, j) holds the frame's pixel (i·factor + ox, j·factor + oy); None: the block's centre.
        One compute dispatch (``core/offscreen_composite.comp``)."""
        frame.reset_state()                 # the sprites' depth test and point size are done
        p = self.gpu.program(compute_shader="core/offscreen_composite.comp",
                             defines={"COMPOSITE_MEDIUM": int(medium),
                                      "COMPOSITE_DISTANCE": (2 if first else 1) if distance else 0})
        centre = 0.5 * (factor - 1)
        write_uniforms(p, factor=factor, inv_near_far=(1.0 / near, 1.0 / far), edge=EDGE,
                       sample_offset=(centre, centre) if offset is None else tuple(float(v) for v in offset))
        color = frame.resource(COLOR)
        textures = {"clouds": self.color, "cloud_depth": self.depth, "scene_depth": DEPTH}
        images = {"color_image": color}
        if distance:
            textures["cloud_distance"] = self.distance
            images["distance_image"] = frame.resource(CLOUD_DISTANCE)
        frame.dispatch(p, work_groups(color.size, (8, 8)), textures=textures, images=images)
