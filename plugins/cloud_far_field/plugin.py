"""CloudFarFieldPlugin and its pass: the clouds beyond the simulated volume, out to the horizon."""
from __future__ import annotations

import numpy as np

from atmos.camera import set_camera_uniforms
from atmos.composition import CLOUD_DISTANCE, composition
from atmos.graph import FullscreenPass, PassContext
from atmos.plugin import Plugin
from atmos.plugins.cloud_far_field.cover import fbm_quantiles
from atmos.plugins.cloud_far_field.settings import CloudFarFieldSettings
from atmos.plugins.cloud_render.light import light_uniforms
from atmos.plugins.clouds.sets import CLOUD_SETS, CloudSets
from atmos.plugins.sky_layer.octaves import OctaveTextures
from atmos.render_core import COLOR, DEPTH

REBAKE_TOLERANCE = 0.05      # re-bake the octaves when the sun moved the light step by this fraction


def drift(settings: CloudFarFieldSettings, time: float) -> np.ndarray:
    """(4, 2) offsets of the octaves in tiles, wrapped to [0, 1): the whole pattern moves with ``wind``."""
    shift = np.asarray(settings.wind, np.float64) * float(time) / settings.tile_size
    return np.mod(np.broadcast_to(shift, (4, 2)), 1.0)


class CloudFarFieldPass(FullscreenPass):
    """Phase translucent, before the cloud renderers (its clouds are behind theirs): blends the far
    field onto ``color`` (premultiplied) where the layer's middle plane is in front of ``depth``, and
    its distance onto ``"cloud_distance"`` when a media pass reads it (:mod:`atmos.composition`)."""
    name = "cloud_far_field"
    phase = "translucent"
    fragment = "cloud_far_field/far.frag"
    reads = (COLOR, DEPTH, CLOUD_SETS)

    def setup(self, builder) -> None:
        super().setup(builder)
        if self.plugin.composition.distance:
            builder.read(CLOUD_DISTANCE)
            builder.write(CLOUD_DISTANCE)

    def prepare(self, gpu) -> None:
        super().prepare(gpu)
        self.octaves = OctaveTextures(gpu)
        self.cover_program = gpu.program(compute_shader="cloud_far_field/cover.comp")
        self.cover = gpu.track(gpu.ctx.buffer(reserve=4))

    def measure_cover(self, sim: CloudSets) -> None:
        """The simulation's edge-weighted cover into the 4-byte buffer the fragment shader reads."""
        c = self.cover_program
        sim.maps_of(sim.a).sums.use(0)
        sim.maps_of(sim.b).sums.use(1)
        c["t"].value = float(sim.t)
        c["a_shift"].value = sim.a_shift[0], sim.a_shift[2]
        c["threshold"].value = float(sim.settings.cover_threshold)
        c["edge_fade"].value = float(sim.settings.edge_fade)
        self.cover.bind_to_storage_buffer(0)
        c.run(1)
        self.gpu.ctx.memory_barrier()

    def execute(self, frame: PassContext) -> None:
        params = self.plugin.settings
        if not params.enabled:
            return
        view, p = frame.view, self.program
        sim: CloudSets = frame.resource(CLOUD_SETS)
        sun_dir = light_uniforms(sim.settings, view.sun)["sun_dir"]
        if self.octaves.needs_bake(params, sun_dir, REBAKE_TOLERANCE):
            self.octaves.bake(params, sun_dir)
        self.measure_cover(sim)
        layout = sim.layout()
        distance = frame.declares(CLOUD_DISTANCE)
        frame.framebuffer(color=[COLOR, CLOUD_DISTANCE] if distance else [COLOR]).use()
        frame.blend_over()
        self.octaves.use(5)
        frame.resource(DEPTH).use(9)
        self.cover.bind_to_storage_buffer(0)
        set_camera_uniforms(p, view.camera, view.aspect)
        camera = np.asarray(view.camera.position, np.float64)
        time = float(view.time) if params.animate else 0.0
        values = dict(light_uniforms(sim.settings, view.sun),
                      camera_uv=tuple(np.mod(camera[[0, 2]] / params.tile_size, 1.0)),
                      mid_height=float(0.5 * (layout.lo[1] + layout.hi[1])),
                      footprint_min=tuple(layout.lo[[0, 2]]), footprint_size=tuple(layout.hi[[0, 2]] - layout.lo[[0, 2]]),
                      edge_fade=float(sim.settings.edge_fade),
                      lod_scale=float(params.size / params.tile_size * 2.0 * np.tan(view.camera.fov_y / 2)
                                      / max(view.size[1], 1)),
                      **{name: float(getattr(params, name)) for name in
                         ("tile_size", "softness", "thickness", "optical_depth", "horizon_fade")})
        for name, value in values.items():
            if name in p:
                p[name].value = value
        p["offsets"].write(drift(params, time).astype("f4").tobytes())
        p["quantiles"].write(np.asarray(fbm_quantiles(params.base_frequency, params.seed), "f4").tobytes())
        frame.fullscreen(p)

    def release(self) -> None:
        octaves, cover = getattr(self, "octaves", None), getattr(self, "cover", None)
        if octaves is not None:
            octaves.release()
            self.octaves = None
        if cover is not None:
            cover.release()
            self.cover = None


class CloudFarFieldPlugin(Plugin):
    """Clouds to the horizon: ``CloudFarFieldPlugin(settings=None, **fields)`` with
    :class:`CloudFarFieldSettings`; needs a CloudsPlugin (its "cloud_sets"), whose ``edge_fade``
    sets the band over which the volume fades out and the far field fades in. ``configure(**changes)``
    changes any setting live (next frame; texture settings re-bake the octaves)."""

    settings_class = CloudFarFieldSettings

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("CloudFarFieldPlugin needs an App with a GPU context (App(gpu))")
        self.composition = composition(app)
        self.composition.writers.add("cloud_far_field")   # the fog gets the layer's own distance
        self.pass_ = CloudFarFieldPass(self)
        app.graph.add_pass(self.pass_)

    def cleanup(self, app) -> None:
        comp = getattr(self, "composition", None)
        if comp is not None:
            comp.writers.discard("cloud_far_field")

    def finish(self, app) -> None:
        """Run before every other translucent pass (the cloud renderers draw nearer clouds over it)."""
        self.pass_.before = tuple(p.name for p in app.graph.passes
                                  if p.phase == "translucent" and p is not self.pass_)
