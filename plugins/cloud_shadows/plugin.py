"""CloudShadowsPlugin: darkens the scene's surfaces where the cloud layer blocks the sun (thesis 7.3.1)."""
from __future__ import annotations

from atmos.camera import Camera, set_camera_uniforms
from atmos.checks import plugin_params
from atmos.graph import FullscreenPass, PassContext
from atmos.lighting import scene_sun
from atmos.plugin import Plugin
from atmos.plugins.clouds.layout import CloudLayout
from atmos.plugins.cloud_shadows.params import CloudShadowParams
from atmos.plugins.cloud_shadows.reference import direct_weight, unit_sun
from atmos.plugins.clouds.simulation import CloudSimulation
from atmos.render_core import COLOR, DEPTH


def cloud_layout(sim: CloudSimulation, params: CloudShadowParams) -> CloudLayout:
    """The volume's world placement (:meth:`CloudSimulation.layout`), with ``params.base_altitude``
    and ``params.cell_size`` where they are set."""
    return sim.layout(params.base_altitude, params.cell_size)


class CloudShadowsPass(FullscreenPass):
    """Multiplies "color" by the shadow factor where "depth" has geometry (blend ZERO, SRC_COLOR)."""
    name = "cloud_shadows"
    fragment = "cloud_shadows/shadow.frag"
    reads = (DEPTH,)

    def execute(self, frame: PassContext) -> None:
        app, gpu, p = frame.data["app"], frame.gpu, self.program
        params = self.plugin.params
        sun = scene_sun(app)
        weight = direct_weight(sun.direction, sun.color, params)
        if weight <= 0.0 or params.strength == 0.0:
            return                                  # no direct light to take away: nothing to draw
        sim = app.resource(CloudSimulation)
        layout = cloud_layout(sim, params)
        sigma = sim.settings.sigma if params.sigma is None else params.sigma
        a, b, t = sim.view()
        frame.framebuffer(color=[COLOR]).use()
        ctx = gpu.ctx
        ctx.enable(ctx.BLEND)
        ctx.blend_func = ctx.ZERO, ctx.SRC_COLOR, ctx.ZERO, ctx.ONE    # alpha (sky occlusion) kept
        sim.maps_of(a).sums.use(0)
        sim.maps_of(b).sums.use(1)
        frame.texture(DEPTH).use(2)
        set_camera_uniforms(p, app.resource(Camera), gpu.size[0] / gpu.size[1])
        p["sun_dir"].value = tuple(unit_sun(sun.direction))
        p["weight"].value = weight
        p["extinction"].value = sigma * params.strength
        p["t"].value = t
        p["layer_min"].value = tuple(float(v) for v in layout.lo)
        p["cell_size"].value = layout.cell
        p["shape"].value = layout.shape
        frame.fullscreen(p)


class CloudShadowsPlugin(Plugin):
    """Ground shadows of the clouds of a CloudsPlugin (add it after the passes that draw the ground
    or terrain, before the clouds themselves); ``params``: :class:`CloudShadowParams`, or its fields
    as keywords. Set ``plugin.params = plugin.params.replace(...)`` to change them while running."""

    def __init__(self, params: CloudShadowParams | None = None, **fields):
        if params is not None and fields:
            raise ValueError("give CloudShadowsPlugin either a CloudShadowParams or its fields as keywords, not both")
        self.params = plugin_params("CloudShadowsPlugin", CloudShadowParams, params, fields)

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("CloudShadowsPlugin needs an App with a GPU context (App(gpu))")
        app.graph.add_pass(CloudShadowsPass(self))
