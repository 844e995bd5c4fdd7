"""The passes every rendered scene has: clear (creates the HDR colour and depth) and present (to the screen).

The ``color`` target's alpha: how much each pixel is occluded from the sky
-------------------------------------------------------------------------
``color.rgb`` is linear HDR radiance; ``color.a`` is how much of the pixel hides the sky behind it:
**0 = open sky, 1 = opaque geometry or opaque cloud** (in between: partly covered, e.g. a cloud edge).
Every pass that writes ``color`` keeps to it; the light shafts' occlusion mask reads it
(:class:`atmos.plugins.light_shafts.LightShaftSettings`), so bright sunlit clouds over the sky cut the
shafts instead of casting them.

- The clear pass clears alpha to 0 (nothing drawn is open sky); the sky passes (``sky``,
  ``sky_gradient``, compute) write alpha 0, only where nothing was drawn (each pixel tests its depth
  for 1), so a frame the game drew first (:mod:`atmos.host_frame`) keeps its pixels.
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

from dataclasses import dataclass, field
from typing import Callable

import moderngl
import numpy as np

from atmos.checks import CheckedSettings, bool_field, num_field, vec_field
from atmos.composition import composition
from atmos.hashing import lowbias32

from atmos.graph import ComputePass, PassBuilder, PassContext, RenderPass, TextureDesc
from atmos.plugin import Plugin
from atmos.scene_uniforms import set_scene_uniforms
from atmos.gpu.uniforms import bind_textures, write_uniforms

SCREEN = "screen"
PRESENT_IMAGE = "present_image"      # the presented frame, 8-bit levels, before its copy to the screen
COLOR = "color"
DEPTH = "depth"
CAMERA_EXPOSURE = "camera_exposure"  # buffer: the exposure (and bloom weight) written on the GPU (shaders/lib/camera.glsl)
BLOOM = "bloom"                      # half-size blurred colour the present mixes in (plugins/physical_camera)
MOTION = "motion"                    # moving geometry's world-space motion since the last frame (:class:`MotionTargets`)


@dataclass
class PresentInputs:
    """App resource: what the present takes besides ``color``. A pass cannot declare an optional read,
    so a plugin that writes :data:`CAMERA_EXPOSURE` (and :data:`BLOOM`) sets ``camera`` (and ``bloom``) to
    a zero-argument callable that says whether it does this frame; None or False: the present uses
    ``RenderCoreSettings.exposure`` and no bloom."""
    camera: Callable[[], bool] | None = None
    bloom: Callable[[], bool] | None = None


def present_inputs(app) -> PresentInputs:
    """The App's :class:`PresentInputs` (made on first use)."""
    return app.init_resource(PresentInputs)


@dataclass
class MotionTargets:
    """App resource: who draws and who reads :data:`MOTION`, a texture of the frame's size whose pixel
    holds (world position now − its position in the last frame, in metres; the depth the drawing
    fragment wrote) where moving geometry was drawn, and alpha −1 elsewhere. The depth tags each motion
    with its surface: a reader takes it only where it equals the depth buffer's within two steps of its
    24 bits (an opaque pass drawn later over the mesh leaves a stale motion that no longer matches).

    A pass cannot declare an optional read, so a pass that draws motion adds its name to ``writers``
    in ``build`` and a reader registers ``readers[name]``, a zero-argument callable saying whether it
    reads this frame; while both are there (:attr:`wanted`) the writer creates :data:`MOTION` (cleared
    first) and the readers read it. A scene without moving geometry or without a reader allocates none."""
    writers: set = field(default_factory=set)
    readers: dict = field(default_factory=dict)

    @property
    def wanted(self) -> bool:
        return bool(self.writers) and any(wants() for wants in self.readers.values())


MOTION_NONE = (0.0, 0.0, 0.0, -1.0)      # the motion target's clear value: no moving surface (alpha −1)
MOTION_DEPTH_TOLERANCE = 2.0 ** -23      # a motion's depth tag against the depth buffer: two 24-bit steps


def motion_targets(app) -> MotionTargets:
    """The App's :class:`MotionTargets` (made on first use)."""
    return app.init_resource(MotionTargets)


def motion_desc(size) -> TextureDesc:
    """The motion target at ``size`` (w, h): rgba32f (the depth tag needs float32), sampled with texelFetch."""
    return TextureDesc(tuple(size), components=4, dtype="f4", filter="nearest")


def color_desc(gpu) -> TextureDesc:
    """The HDR colour: drawn into, blended onto, and read-modified-written by compute passes (an rgba16f image)."""
    return TextureDesc(gpu.size, components=4, dtype="f2", storage=True)


def depth_desc(gpu) -> TextureDesc:
    return TextureDesc(gpu.size, depth=True)


class ClearPass(RenderPass):
    """Creates the scene's HDR ``color`` and ``depth`` textures and clears them: colour to
    ``(*clear_color, 0)`` (alpha 0: open sky, see the module docstring), depth to 1. The colour is left
    uncleared where a pass fills every pixel of it before the geometry (``Composition.backgrounds``: a sky,
    which then writes every pixel, or the game's own frame)."""
    name = "clear"
    phase = "clear"

    def __init__(self, gpu, plugin: "RenderCorePlugin", composition):
        self.gpu = gpu
        self.plugin = plugin
        self.composition = composition

    def setup_key(self) -> tuple:
        return (self.gpu.size,)

    def setup(self, builder: PassBuilder) -> None:
        builder.create(COLOR, color_desc(self.gpu))
        builder.create(DEPTH, depth_desc(self.gpu))

    def execute(self, frame: PassContext) -> None:
        if self.composition.backgrounds:
            frame.framebuffer(depth=DEPTH).clear(depth=1.0)
            return
        fbo = frame.framebuffer(color=[COLOR], depth=DEPTH)
        fbo.use()
        fbo.clear(*self.plugin.settings.clear_color, 0.0, depth=1.0)


DITHER_STEP = 1.0 / 255.0     # one step of 8-bit output
HDR_MAX = 16384.0             # the most light one effect adds to a colour pixel (shaders/lib/hdr_max.glsl)


def tone_map(hdr, exposure: float = 1.0) -> np.ndarray:
    """Display values in [0, 1] of linear HDR colours (``core/present.comp`` before dithering and
    rounding): exposure, the ACES fit of Narkowicz, then gamma 1/2.2."""
    x = np.maximum(np.asarray(hdr, np.float64) * exposure, 0.0)
    return np.clip((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0) ** (1.0 / 2.2)


def dither_offsets(width: int, height: int) -> np.ndarray:
    """(height, width, 3) triangular dither in (−1, 1) that present adds (× ``DITHER_STEP``) to each
    pixel, rows bottom-up like ``gl_FragCoord``: per pixel a hash, per channel the sum of two 16-bit
    uniforms minus 1 (bit for bit the GLSL's hash)."""
    y, x = np.mgrid[0:height, 0:width].astype(np.uint32)
    with np.errstate(over="ignore"):
        h = lowbias32((x * np.uint32(0x9E3779B9)) ^ lowbias32(y + np.uint32(0x2F6B4D5D)))
    total = np.zeros((height, width, 3))
    for i in range(2):
        a, b = lowbias32(h + np.uint32(2 * i)), lowbias32(h + np.uint32(2 * i + 1))
        total += np.stack([a & 0xFFFF, a >> 16, b & 0xFFFF], axis=-1) / 65536.0
    return total - 1.0


def present_levels(hdr, exposure: float = 1.0, dither: bool = True) -> np.ndarray:
    """The 8-bit levels (0..255, float64) ``core/present.comp`` writes for an (h, w, 3) HDR image, rows
    bottom-up: :func:`tone_map`, plus :func:`dither_offsets` × ``DITHER_STEP`` when ``dither``, rounded
    to the nearest level (the shader writes exactly level / 255, so the conversion to
    8 bits keeps it whatever its rounding)."""
    x = tone_map(hdr, exposure)
    if dither:
        x = x + DITHER_STEP * dither_offsets(x.shape[1], x.shape[0])
    return np.clip(np.floor(x * 255.0 + 0.5), 0.0, 255.0)


class PresentPass(ComputePass):
    """Tone-maps the HDR ``color`` for the screen (window or offscreen target), with sRGB gamma
    and (``RenderCoreSettings.dither``) a triangular dither of one 8-bit step against banding,
    rounded to 8-bit levels in the shader (:func:`present_levels`): one compute invocation per pixel
    into ``"present_image"`` (rgba8), then one framebuffer blit to the screen (a multisampled screen,
    which a blit writes only from its own format, gets it drawn 1:1). The screen's alpha is 1
    (``color.a``, the sky occlusion, is not shown). With a physical camera (:class:`PresentInputs`) the
    exposure and the bloom's weight come from its buffer and the bloom is mixed in first."""
    name = "present"
    phase = "present"
    compute = "core/present.comp"
    copy = "core/present_copy.frag"
    camera = bloom = False               # this frame's inputs (setup)

    def _inputs(self) -> tuple[bool, bool]:
        """(a physical camera's exposure, its bloom) this frame (:class:`PresentInputs`)."""
        inputs = self.plugin.inputs
        camera = bool(inputs.camera is not None and inputs.camera())
        return camera, bool(camera and inputs.bloom is not None and inputs.bloom())

    def setup_key(self) -> tuple:
        return (*self._inputs(), self.plugin.gpu.size)

    def setup(self, builder: PassBuilder) -> None:
        self.camera, self.bloom = self._inputs()
        if self.camera:
            builder.read(CAMERA_EXPOSURE, access="storage")
        if self.bloom:
            builder.read(BLOOM)
        builder.read(COLOR)
        builder.create(PRESENT_IMAGE, TextureDesc(tuple(self.plugin.gpu.size), components=4, dtype="f1",
                                                  filter="nearest", storage=True), access="storage")
        builder.write(SCREEN)

    def defines(self) -> dict:
        return {"CAMERA": int(self.camera), "BLOOM": int(self.bloom)}

    def execute(self, frame: PassContext) -> None:
        p = self.program
        write_uniforms(p, dither=DITHER_STEP if self.plugin.settings.dither else 0.0)
        if not self.camera:                               # else the camera's buffer holds it
            write_uniforms(p, exposure=self.plugin.settings.exposure)
        image = frame.image(PRESENT_IMAGE)
        frame.dispatch(p, self.groups(image.size), textures={"hdr": COLOR, "bloom_image": BLOOM} if self.bloom
                       else {"hdr": COLOR}, images={"screen_image": PRESENT_IMAGE},
                       buffers={"Camera": CAMERA_EXPOSURE} if self.camera else None)
        screen = frame.resource(SCREEN)
        screen.use()                                      # its scissor off: a blit obeys it
        if screen.samples:
            copy = self.gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader=self.copy)
            bind_textures(copy, screen_image=image)
            frame.fullscreen(copy)
            return
        frame.gpu.hazards.use(reads=[(image, "attachment"), (image, "copy")])   # the blit sees the stores
        frame.gpu.ctx.copy_framebuffer(screen, frame.framebuffer(color=[PRESENT_IMAGE]))


class OpaquePass(RenderPass):
    """Depth-tested geometry drawn into ``color`` and ``depth`` (phase opaque, alpha 1). A subclass makes
    ``self.program`` in ``prepare`` and starts its ``execute`` with :meth:`begin`."""
    phase = "opaque"
    program = None

    def setup_key(self) -> tuple:
        return ()                           # the same declarations every frame

    def setup(self, builder: PassBuilder) -> None:
        builder.write(COLOR)
        builder.read(DEPTH)                 # depth-tested
        builder.write(DEPTH)

    def begin(self, frame: PassContext) -> None:
        """Bind colour and depth, turn the depth test on, write the camera and sun uniforms."""
        frame.framebuffer(color=[COLOR], depth=DEPTH).use()
        frame.gpu.ctx.enable(moderngl.DEPTH_TEST)
        set_scene_uniforms(self.program, frame.view)


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


class LinearCapturePass(CapturePass):
    """:meth:`atmos.App.read_linear`'s pass: a CapturePass that reads back only while ``armed``."""
    name = "read_linear"
    armed = False

    def execute(self, frame: PassContext) -> None:
        if self.armed:
            super().execute(frame)


@dataclass(frozen=True)
class RenderCoreSettings(CheckedSettings):
    """How each frame starts and how it reaches the screen (all live)."""
    clear_color: tuple = vec_field((0.0, 0.0, 0.0), 3, "non-negative", "linear HDR colour ``color`` starts "
                                   "each frame with")
    exposure: float = num_field(1.0, 0.0, 1e6, "HDR scale before tone mapping (a PhysicalCameraPlugin's exposure, "
                                "metered or in EV100, replaces it)", lo_open=True)
    dither: bool = bool_field(True, "add a triangular dither of ±1 step before 8-bit output (mean unchanged, "
                              "no banding)")


class RenderCorePlugin(Plugin):
    """Imports the screen into the render graph and adds the clear and present passes:
    ``RenderCorePlugin(settings=None, **fields)`` with :class:`RenderCoreSettings`;
    ``configure(**changes)`` changes any of them live (next frame)."""

    settings_class = RenderCoreSettings

    def build(self, app) -> None:
        if app.graph is None:
            return
        self.gpu = app.gpu
        self.inputs = present_inputs(app)
        app.graph.import_resource(SCREEN, lambda: app.gpu.target)
        app.graph.add_pass(ClearPass(app.gpu, self, composition(app)))
        app.graph.add_pass(PresentPass(self))
