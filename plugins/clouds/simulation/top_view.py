"""A top view of the cloud field: the summed density maps of sets A and B, interpolated, on screen.

What the thesis's Figure 7.3 shows; the `cloud_field` demo uses it until the sprite renderer draws
the clouds in 3D.
"""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, num_field
from atmos.graph import FullscreenPass, PassContext
from atmos.plugin import Plugin
from atmos.plugins.clouds.volume.sets import CLOUD_SETS, CloudSets
from atmos.render_core import COLOR
from atmos.gpu.uniforms import bind_textures


class CloudTopViewPass(FullscreenPass):
    name = "cloud_top_view"
    phase = "opaque"
    fragment = "clouds/simulation/top_view.frag"
    reads = (CLOUD_SETS,)

    def execute(self, frame: PassContext) -> None:
        sim: CloudSets = frame.resource(CLOUD_SETS)
        a, b, t = sim.view()
        frame.framebuffer(color=[COLOR]).use()
        bind_textures(self.program, sums_a=sim.maps_of(a).sums, sums_b=sim.maps_of(b).sums)
        self.program["t"].value = t
        self.program["a_shift"].value = sim.a_shift[0], sim.a_shift[2]
        self.program["full"].value = self.plugin.settings.full_column
        self.program["aspect"].value = frame.view.aspect
        frame.fullscreen(self.program)


@dataclass(frozen=True)
class CloudTopViewSettings(CheckedSettings):
    """How bright the top view draws the summed density (live)."""
    full_column: float = num_field(4.0, 0.0, doc="the summed density (cells) drawn fully white", lo_open=True)


class CloudTopViewPlugin(Plugin):
    """Draws the cloud field seen from above: ``CloudTopViewPlugin(settings=None, **fields)`` with
    :class:`CloudTopViewSettings`; ``configure(full_column=...)`` changes it on the next frame."""

    settings_class = CloudTopViewSettings

    def build(self, app) -> None:
        app.graph.add_pass(CloudTopViewPass(self))
