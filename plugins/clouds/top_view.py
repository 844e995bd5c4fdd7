"""A top view of the cloud field: the summed density maps of sets A and B, interpolated, on screen.

What the thesis's Figure 7.3 shows; the `cloud_field` demo uses it until the sprite renderer draws
the clouds in 3D.
"""
from __future__ import annotations

from atmos.graph import FullscreenPass, PassContext
from atmos.plugin import Plugin
from atmos.plugins.clouds.simulation import CloudSimulation
from atmos.render_core import COLOR


class CloudTopViewPass(FullscreenPass):
    name = "cloud_top_view"
    fragment = "clouds/top_view.frag"

    def execute(self, frame: PassContext) -> None:
        sim = frame.data["app"].resource(CloudSimulation)
        a, b, t = sim.view()
        frame.framebuffer(color=[COLOR]).use()
        sim.maps_of(a).sums.use(0)
        sim.maps_of(b).sums.use(1)
        self.program["t"].value = t
        self.program["full"].value = self.plugin.full_column
        self.program["aspect"].value = frame.gpu.size[0] / frame.gpu.size[1]
        frame.fullscreen(self.program)


class CloudTopViewPlugin(Plugin):
    """Draws the cloud field seen from above; ``full_column``: summed density drawn fully white."""

    def __init__(self, full_column: float = 4.0):
        self.full_column = full_column

    def build(self, app) -> None:
        app.graph.add_pass(CloudTopViewPass(self))
