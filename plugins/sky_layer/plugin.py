"""SkyLayerPlugin and its pass: the 2D dynamic cloud layer drawn where the sky is visible."""
from __future__ import annotations

import numpy as np

from atmos.graph import ComputePass, PassContext
from atmos.lighting import Sun, sun_and_day
from atmos.plugin import Plugin
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import write_uniforms
from atmos.tile_octaves import OctaveTextures
from atmos.plugins.sky_layer.settings import SkyLayerSettings


def layer_light(sun: Sun) -> tuple[np.ndarray, np.ndarray]:
    """(unit direction toward the sun, light on the clouds): the sun colour by day plus a little sky light."""
    s, day = sun_and_day(sun)
    return s, np.asarray(sun.color, np.float64) * day + 0.15 * (0.1 + 0.9 * day)


def scroll_offsets(wind, time: float) -> np.ndarray:
    """(4, 2) scroll of each octave at ``time``, wrapped to [0, 1) (the textures repeat with period 1)."""
    return np.mod(np.asarray(wind, np.float64) * float(time), 1.0)


class SkyLayerPass(ComputePass):
    """Phase sky, after the sky itself (it composites onto ``color``); reads ``depth`` and draws where it
    is 1 (so it also composes over geometry drawn before it), one compute invocation per pixel
    (``sky_layer/layer.comp``), premultiplied over colour and alpha, so ``color.a`` gains their cover of
    the sky."""
    name = "sky_layer"
    phase = "sky"
    compute = "sky_layer/layer.comp"
    reads = (COLOR, DEPTH)
    writes = (COLOR,)

    def prepare(self, gpu) -> None:
        super().prepare(gpu)
        self.plugin.octaves = OctaveTextures(gpu)

    def execute(self, frame: PassContext) -> None:
        view, p, plugin = frame.view, self.program, self.plugin
        params = plugin.settings
        s, light = layer_light(view.sun)
        if plugin.octaves.needs_bake(params, s, params.rebake_tolerance):
            plugin.octaves.bake(params, s)
        plugin.octaves.bind(p)
        p["offsets"].write(scroll_offsets(params.wind, plugin.time(view)).astype("f4").tobytes())
        write_uniforms(p, light=tuple(light), lod_scale=float(params.size / params.tile_size * 2.0
                                                               * np.tan(view.camera.fov_y / 2) / max(view.size[1], 1)),
                       **{name: getattr(params, name) for name in ("altitude", "tile_size", "horizon_fade", "emptiness",
                                                                   "sharpness", "thickness", "color", "lit_color")})
        color = frame.image(COLOR)
        frame.dispatch(p, self.groups(color.size), textures={"scene_depth": DEPTH}, images={"color_image": color})

    def release(self) -> None:
        if self.plugin.octaves is not None:
            self.plugin.octaves.release()
            self.plugin.octaves = None


class SkyLayerPlugin(Plugin):
    """The 2D dynamic cloud layer: ``SkyLayerPlugin(settings=None, **fields)`` with :class:`SkyLayerSettings`.

    ``configure(**changes)`` changes any of them live (next frame; texture settings re-bake the
    octaves, as does the sun turning by more than ``rebake_tolerance`` of a light step). Scrolling
    follows ``clock.frame_time`` unless ``animate=False``.
    """

    settings_class = SkyLayerSettings

    def __init__(self, settings: SkyLayerSettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.octaves: OctaveTextures | None = None      # made by the pass's prepare

    def time(self, view) -> float:
        """Seconds the octaves have scrolled for: the view's frame time (0 unless ``animate``)."""
        return float(view.time) if self.settings.animate else 0.0

    def build(self, app) -> None:
        app.graph.add_pass(SkyLayerPass(self))
