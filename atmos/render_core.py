"""The passes every rendered scene has: clear (creates the HDR colour and depth) and present (to the screen).

The ``color`` target's alpha: how much each pixel is occluded from the sky
-------------------------------------------------------------------------
``color.rgb`` is linear HDR radiance; ``color.a`` is how much of the pixel hides the sky behind it:
**0 = open sky, 1 = opaque geometry or opaque cloud** (in between: partly covered, e.g. a cloud edge).
Every pass that writes ``color`` keeps to it; the light shafts' occlusion mask reads it
(:class:`atmos.plugins.light_shafts.LightShaftSettings`), so bright sunlit clouds over the sky cut the
shafts instead of casting them.

- The clear pass clears alpha to 0 (nothing drawn is open sky); the sky passes (``sky``,
  ``sky_gradient``) write alpha 0.
- Opaque geometry (``ground``, ``terrain``, the clouds' top view) writes alpha 1 (blending off).
- Layers that cover the sky blend premultiplied ``(light, coverage a)`` with (ONE, ONE_MINUS_SRC_ALPHA)
  on colour *and* alpha (:meth:`PassContext.blend_over`): ``alpha = a + (1 − a) · alpha``. The cloud
  sprites and the reference march (``cloud_render``), the 2D cloud layer (``sky_layer``) and the test
  volume do so.
- Participating media in the air between the camera and everything (``fog``, ``volumetric_fog``)
  blend ``(light, transmittance)`` with (ONE, SRC_ALPHA) on colour and keep alpha
  (:meth:`PassContext.blend_transmittance`): fog is not an occluder. The sky seen through it stays
  sky; what the fog does to it (dimmed toward the fog colour) is in the colour, which the shaft mask
  thresholds, so the sun seen through thin fog still casts (dimmed) shafts and a uniformly fogged
  sky only glows.
- Passes that modulate surfaces (``cloud_shadows``: colour × factor) or add light (the light shafts'
  composite) keep alpha.
- ``present`` writes alpha 1 to the screen whatever ``color.a`` is; the frame-time overlay blended
  onto the screen keeps it 1.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, check_num, check_vec

from atmos.graph import FullscreenPass, PassBuilder, PassContext, RenderPass, TextureDesc
from atmos.plugin import Plugin

SCREEN = "screen"
COLOR = "color"
DEPTH = "depth"


def color_desc(gpu) -> TextureDesc:
    return TextureDesc(gpu.size, components=4, dtype="f2")


def depth_desc(gpu) -> TextureDesc:
    return TextureDesc(gpu.size, depth=True)


class ClearPass(RenderPass):
    """Creates the scene's HDR ``color`` and ``depth`` textures and clears them: colour to
    ``(*clear_color, 0)`` (alpha 0: open sky, see the module docstring), depth to 1."""
    name = "clear"
    phase = "clear"

    def __init__(self, gpu, plugin: "RenderCorePlugin"):
        self.gpu = gpu
        self.plugin = plugin

    def setup(self, builder: PassBuilder) -> None:
        builder.create(COLOR, color_desc(self.gpu))
        builder.create(DEPTH, depth_desc(self.gpu))

    def execute(self, frame: PassContext) -> None:
        fbo = frame.framebuffer(color=[COLOR], depth=DEPTH)
        fbo.use()
        fbo.clear(*self.plugin.settings.clear_color, 0.0, depth=1.0)


class PresentPass(FullscreenPass):
    """Tone-maps the HDR ``color`` into the screen (window or offscreen target), with sRGB gamma;
    the screen's alpha is 1 (``color.a``, the sky occlusion, is not shown)."""
    name = "present"
    phase = "present"
    fragment = "core/present.frag"
    reads = (COLOR,)
    writes = (SCREEN,)

    def execute(self, frame: PassContext) -> None:
        frame.resource(SCREEN).use()
        frame.resource(COLOR).use(0)
        self.program["exposure"].value = self.plugin.settings.exposure
        frame.fullscreen(self.program)


class CapturePass(RenderPass):
    """Copies the final HDR ``color`` (float, (h, w, 4)) and ``depth`` ((h, w)) to numpy each frame,
    rows bottom-up as OpenGL stores them. For tests, tools and HDR screenshots; a side effect."""
    name = "capture"
    phase = "readback"

    def __init__(self):
        self.color = self.depth = None

    def setup(self, builder: PassBuilder) -> None:
        builder.read(COLOR)
        builder.read(DEPTH)
        builder.side_effect()

    def execute(self, frame: PassContext) -> None:
        w, h = frame.gpu.size
        self.color = np.frombuffer(frame.resource(COLOR).read(), np.float16).reshape(h, w, 4).astype(np.float64)
        self.depth = np.frombuffer(frame.resource(DEPTH).read(), np.float32).reshape(h, w).astype(np.float64)


@dataclass(frozen=True)
class RenderCoreSettings(CheckedSettings):
    """``clear_color``: linear HDR colour ``color`` starts each frame with (non-negative);
    ``exposure``: HDR scale before tone mapping (> 0). All live."""
    clear_color: tuple = (0.0, 0.0, 0.0)
    exposure: float = 1.0

    def __post_init__(self):
        o = "RenderCoreSettings"
        self.store(dict(clear_color=check_vec(o, "clear_color", self.clear_color, 3, "non-negative"),
                        exposure=check_num(o, "exposure", self.exposure, 0.0, 1e6, lo_open=True)))


class RenderCorePlugin(Plugin):
    """Imports the screen into the render graph and adds the clear and present passes:
    ``RenderCorePlugin(settings=None, **fields)`` with :class:`RenderCoreSettings`;
    ``configure(**changes)`` changes any of them live (next frame)."""

    settings_class = RenderCoreSettings

    def build(self, app) -> None:
        if app.graph is None:
            return
        app.graph.import_resource(SCREEN, lambda: app.gpu.target)
        app.graph.add_pass(ClearPass(app.gpu, self))
        app.graph.add_pass(PresentPass(self))
