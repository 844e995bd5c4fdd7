"""A large ground plane at height 0 with a procedural checker, lit by the sun, faded into the distance."""
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, num_field, vec_field

from atmos.graph import PassContext
from atmos.gpu.uniforms import write_uniforms
from atmos.lighting import GroundSurface
from atmos.plugins.sky.light import SkyLight
from atmos.plugin import Plugin
from atmos.render_core import OpaquePass


@dataclass(frozen=True)
class GroundSettings(CheckedSettings):
    """A flat checkered ground plane at y = 0 (all live)."""
    half_size: float = num_field(4000.0, 0.0, doc="the plane reaches this many metres each way from the origin",
                                 lo_open=True)
    tile: float = num_field(4.0, 0.0, doc="checker tiles of this many metres", lo_open=True)
    albedo: tuple = vec_field((0.28, 0.36, 0.2), 3, "non-negative", "linear RGB reflectance (physical: at most 1)")
    haze_distance: float = num_field(667.0, 0.0, doc="metres over which the plane fades (e-folding) into the sky's "
                                     "horizon light (:func:`haze_color`), hiding its edge; 0: no fade (a fog or "
                                     "the sky's aerial perspective hazes it instead)")


def ground_quad(half_size: float) -> bytes:
    """The plane's four (x, z) corners as a triangle strip."""
    h = half_size
    return np.array([[-h, -h], [h, -h], [-h, h], [h, h]], np.float32).tobytes()


HAZE_GAIN = 2.0     # without a sky's light: the horizon's light over the Sun's ambient (the default day: (0.7, 0.94, 1.3))


def haze_color(view, sky=None) -> np.ndarray:
    """(3,) float64 the plane fades into: the sky's mean horizon light seen from the camera (``sky``, the
    SkyLight a SkyPlugin publishes) or, without one, HAZE_GAIN × the Sun's ambient (dark at night, dim at
    twilight: no bright line at the horizon then)."""
    if sky is not None:
        return sky.mean_horizon(view.sun, max(float(view.camera.position[1]), 0.0))
    return HAZE_GAIN * np.asarray(view.sun.ambient, np.float64)


class GroundPass(OpaquePass):
    name = "ground"

    def __init__(self, plugin: "GroundPlugin"):
        self.plugin = plugin
        self.program = self.vao = self.vbo = None

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="ground/ground.vert", fragment_shader="ground/ground.frag")
        self.half_size = self.plugin.settings.half_size
        self.vbo = gpu.track(gpu.ctx.buffer(ground_quad(self.half_size)))
        self.vao = gpu.track(gpu.ctx.vertex_array(self.program, [(self.vbo, "2f", "in_xz")]))

    def execute(self, frame: PassContext) -> None:
        gpu = frame.gpu
        self.begin(frame)
        settings = self.plugin.settings
        if settings.half_size != self.half_size:           # a live change: the same 4 corners, moved
            self.half_size = settings.half_size
            self.vbo.write(ground_quad(self.half_size))
        write_uniforms(self.program, albedo=settings.albedo, tile=settings.tile,
                       haze_rate=1.0 / settings.haze_distance if settings.haze_distance > 0.0 else 0.0,
                       haze_color=tuple(float(c) for c in haze_color(frame.view, self.plugin.sky)))
        self.vao.render(gpu.ctx.TRIANGLE_STRIP)

    def release(self) -> None:
        for obj in (self.vao, self.vbo):
            if obj is not None:
                obj.release()


class GroundPlugin(Plugin):
    """Ground plane: ``GroundPlugin(settings=None, **fields)`` with :class:`GroundSettings`;
    ``configure(**changes)`` changes any of them live (next frame)."""

    settings_class = GroundSettings

    sky = None          # the scene's SkyLight, where a SkyPlugin publishes one (finish)

    def build(self, app) -> None:
        app.graph.add_pass(GroundPass(self))
        app.insert_resource(GroundSurface(lambda: self.settings.albedo))   # what the clouds' light from below sees

    def finish(self, app) -> None:
        self.sky = app.get_resource(SkyLight)
