"""SkyLayerPlugin and its pass: the 2D dynamic cloud layer drawn where the sky is visible."""
from __future__ import annotations

import numpy as np

from atmos.camera import Camera, set_camera_uniforms
from atmos.checks import plugin_params
from atmos.graph import FullscreenPass, PassContext
from atmos.lighting import Sun, scene_sun, sun_and_day
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.plugins.sky_layer.octaves import OctaveTextures
from atmos.plugins.sky_layer.params import SkyLayerParams


def layer_light(sun: Sun) -> tuple[np.ndarray, np.ndarray]:
    """(unit direction toward the sun, light on the clouds): the sun colour by day plus a little sky light."""
    s, day = sun_and_day(sun)
    return s, np.asarray(sun.color, np.float64) * day + 0.15 * (0.1 + 0.9 * day)


def scroll_offsets(wind, time: float) -> np.ndarray:
    """(4, 2) scroll of each octave at ``time``, wrapped to [0, 1) (the textures repeat with period 1)."""
    return np.mod(np.asarray(wind, np.float64) * float(time), 1.0)


class SkyLayerPass(FullscreenPass):
    """Reads ``depth``; blends the clouds over ``color`` where depth is 1, premultiplied (ONE,
    ONE_MINUS_SRC_ALPHA on colour and alpha), so ``color.a`` gains their cover of the sky."""
    name = "sky_layer"
    fragment = "sky_layer/layer.frag"
    reads = (DEPTH,)

    def prepare(self, gpu) -> None:
        super().prepare(gpu)
        self.plugin.octaves = OctaveTextures(gpu)

    def execute(self, frame: PassContext) -> None:
        app, gpu, p, plugin = frame.data["app"], frame.gpu, self.program, self.plugin
        params = plugin.params
        s, light = layer_light(scene_sun(app))
        if plugin.octaves.needs_bake(params, s, plugin.rebake_tolerance):
            plugin.octaves.bake(params, s)
        frame.framebuffer(color=[COLOR]).use()
        frame.blend_over()
        plugin.octaves.use(0)
        frame.texture(DEPTH).use(4)
        set_camera_uniforms(p, app.resource(Camera), gpu.size[0] / gpu.size[1])
        p["offsets"].write(scroll_offsets(params.wind, plugin.time(app)).astype("f4").tobytes())
        for name in ("altitude", "tile_size", "horizon_fade", "emptiness", "sharpness", "thickness",
                     "color", "lit_color"):
            p[name].value = getattr(params, name)
        p["light"].value = tuple(light)
        frame.fullscreen(p)

    def release(self) -> None:
        if self.plugin.octaves is not None:
            self.plugin.octaves.release()
            self.plugin.octaves = None


class SkyLayerPlugin(Plugin):
    """The 2D dynamic cloud layer; ``SkyLayerParams`` fields as keyword arguments (or ``params=``).

    ``configure(**changes)`` changes settings at run time (all checked before any is applied; texture
    settings re-bake the octaves on the next frame, as does the sun turning by more than
    ``rebake_tolerance`` of a light step). Scrolling follows ``clock.frame_time`` unless ``animate=False``.
    """

    def __init__(self, params: SkyLayerParams | None = None, animate: bool = True,
                 rebake_tolerance: float = 0.05, **settings):
        self.params = plugin_params("SkyLayerPlugin", SkyLayerParams, params, settings)
        if not (isinstance(rebake_tolerance, (int, float)) and 0 <= rebake_tolerance <= 1):
            raise ValueError(f"rebake_tolerance must be a number in 0..1 (fraction of a light step), "
                             f"got {rebake_tolerance!r}")
        self.animate = bool(animate)
        self.rebake_tolerance = float(rebake_tolerance)
        self.octaves: OctaveTextures | None = None      # made by the pass's prepare

    def configure(self, **changes) -> SkyLayerParams:
        """Replace settings at once (checked together; on error nothing changes); returns the new params."""
        self.params = self.params.replace(**changes)
        return self.params

    def time(self, app) -> float:
        return float(app.clock.frame_time) if self.animate else 0.0

    def build(self, app) -> None:
        app.graph.add_pass(SkyLayerPass(self))
