"""CloudFarFieldPlugin and its pass: the clouds beyond the simulated volume, out to the horizon."""
from __future__ import annotations

import numpy as np

from atmos.composition import CLOUD_DISTANCE, composition, distance_desc
from atmos.graph import ComputePass, PassContext
from atmos.plugin import Plugin
from atmos.plugins.clouds.far_field.layer import FarFieldLayer
from atmos.plugins.clouds.light.ground import GROUND, bind_ground, ground_sun_pass
from atmos.plugins.clouds.volume.sets import FAR_FIELD
from atmos.plugins.clouds.far_field.settings import CloudFarFieldSettings
from atmos.plugins.clouds.volume.light import CloudLightSettings, light_uniforms, write_light
from atmos.plugins.clouds.volume.far_link import far_field_link
from atmos.plugins.clouds.volume.field_demand import field_demand
from atmos.plugins.clouds.volume.sets import CLOUD_SETS, CloudSets
from atmos.render_core import COLOR, DEPTH


class CloudFarFieldPass(ComputePass):
    """Phase translucent, before the cloud renderers (its clouds are behind theirs): composites the far
    field onto ``color`` in place (premultiplied, one compute invocation per pixel) where the layer's
    middle plane is in front of ``depth``, and its distance onto ``"cloud_distance"`` when a media pass
    reads it (:mod:`atmos.composition`): as its first writer it creates it and writes every pixel (no clear)."""
    name = "cloud_far_field"
    phase = "translucent"
    compute = "clouds/far_field/far.comp"
    reads = (COLOR, DEPTH, CLOUD_SETS, FAR_FIELD)
    writes = (COLOR,)

    def setup(self, builder) -> None:
        if not self.plugin.runs():
            return                          # off, or a ray march draws the far field volumetrically: culled
        super().setup(builder)
        builder.read(GROUND, access="uniform")
        comp = self.plugin.composition
        if comp.distance_first == self.name:                   # the first writer: every pixel written
            builder.create(CLOUD_DISTANCE, distance_desc(self.plugin.gpu.size), access="storage")
        elif comp.distance:
            builder.read(CLOUD_DISTANCE, access="storage")
            builder.write(CLOUD_DISTANCE, access="storage")

    def defines(self) -> dict:
        comp = self.plugin.composition
        return {"FAR_DISTANCE": 0 if not comp.distance else 2 if comp.distance_first == self.name else 1}

    def execute(self, frame: PassContext) -> None:
        params = self.plugin.settings
        if not params.enabled:
            return
        view, p = frame.view, self.program
        sim: CloudSets = frame.resource(CLOUD_SETS)
        layer: FarFieldLayer = frame.resource(FAR_FIELD)
        layer.prepare(view, sim)
        layout = sim.layout()
        distance = frame.declares(CLOUD_DISTANCE)
        layer.use(p, view, sim)
        light = self.plugin.light_settings()       # the renderer's octaves; its field's weight where measured
        diffusion = light.ms_diffusion if layer.light.has_field else 0.0
        ground = None if view.ground is None else view.ground.albedo
        values = dict(light_uniforms(sim.settings, view.sun, light.octaves, diffusion, layout.heights, ground),
                      footprint_min=tuple(layout.lo[[0, 2]]), footprint_size=tuple(layout.hi[[0, 2]] - layout.lo[[0, 2]]),
                      edge_fade=float(sim.settings.edge_fade), layer_height=float(layout.hi[1] - layout.lo[1]),
                      lod_scale=float(params.size / layer.tile_size * 2.0 * np.tan(view.camera.fov_y / 2)
                                      / max(view.size[1], 1)),
                      **{name: float(getattr(params, name)) for name in
                         ("thickness", "horizon_fade")})
        write_light(p, values)
        bind_ground(p, frame.resource(GROUND))
        images = {"color_image": COLOR, **({"distance_image": CLOUD_DISTANCE} if distance else {})}
        frame.dispatch(p, self.groups(frame.image(COLOR).size), textures={"scene_depth": DEPTH}, images=images)


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
        self.composition.covers["cloud_far_field"] = self.runs    # and it writes all of it (no clear),
        self.composition.behind.add("cloud_far_field")            # behind every other cloud layer
        self.gpu = app.gpu
        self.layer = FarFieldLayer(app.gpu, self)          # also read by the ground shadows
        self.demand = field_demand(app)                    # the cloud renderers (light_settings)
        self.link = far_field_link(app)                    # and those that may march it (drawn_by_march)
        self.link.shown = lambda: bool(self.settings.enabled)
        app.graph.import_resource(FAR_FIELD, self.layer)
        self.pass_ = CloudFarFieldPass(self)
        app.graph.add_pass(self.pass_)
        ground_sun_pass(app.graph)

    def cleanup(self, app) -> None:
        layer = getattr(self, "layer", None)
        if layer is not None:
            layer.release()
        comp = getattr(self, "composition", None)
        if comp is not None:
            comp.writers.discard("cloud_far_field")
            comp.covers.pop("cloud_far_field", None)
            comp.behind.discard("cloud_far_field")
        link = getattr(self, "link", None)
        if link is not None:
            link.shown = None

    def light_settings(self) -> CloudLightSettings:
        """The octaves and field weight the far field is lit with: the renderer's that marches it
        (FarFieldLink.marcher), else the cloud renderer's (FieldDemand.light; the defaults without one), so
        the far clouds continue the volume's light."""
        link = getattr(self, "link", None)
        marcher = link.marcher() if link is not None else None
        if marcher is not None:                 # the renderer that marches the far field lights it
            return marcher.settings
        return self.demand.light() or CloudLightSettings()

    def runs(self) -> bool:
        """Whether the 2D pass draws this frame (enabled, not marched by a cloud renderer)."""
        return self.settings.enabled and not self.drawn_by_march()

    def drawn_by_march(self) -> bool:
        """Whether a cloud renderer marches the far field itself this frame (a registered renderer's
        ``marches_far_field()``, e.g. RaymarchCloudsPlugin with ``far_field``): the 2D pass then
        declares nothing and is culled; the layer stays imported for the shadows and the march."""
        link = getattr(self, "link", None)
        return link is not None and link.marched()

    def finish(self, app) -> None:
        """Run before every other translucent pass (the cloud renderers draw nearer clouds over it)."""
        self.pass_.before = tuple(p.name for p in app.graph.passes
                                  if p.phase == "translucent" and p is not self.pass_)
