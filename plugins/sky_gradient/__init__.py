"""A cheap analytic sky: horizon-to-zenith gradient, a sun disc and glow. Draws the whole background."""
from dataclasses import dataclass

from atmos.checks import CheckedSettings, vec_field
from atmos.graph import FullscreenPass, PassContext
from atmos.plugin import Plugin
from atmos.render_core import DEPTH, where_nothing_was_drawn


@dataclass(frozen=True)
class SkyGradientSettings(CheckedSettings):
    """The gradient's sky colours, linear HDR (all live)."""
    zenith: tuple = vec_field((0.15, 0.35, 0.8), 3, "non-negative", "overhead")
    horizon: tuple = vec_field((0.75, 0.85, 1.0), 3, "non-negative", "at eye level")
    ground: tuple = vec_field((0.35, 0.33, 0.3), 3, "non-negative", "below the horizon")


class SkyGradientPass(FullscreenPass):
    """The gradient where nothing was drawn (depth 1)."""
    name = "sky_gradient"
    phase = "sky"
    fragment = "sky_gradient/sky.frag"
    vertex = "lib/fullscreen_far.vert"
    reads = (DEPTH,)

    def execute(self, frame: PassContext) -> None:
        where_nothing_was_drawn(frame)
        settings = self.plugin.settings
        self.program["zenith"].value = settings.zenith
        self.program["horizon"].value = settings.horizon
        self.program["ground"].value = settings.ground
        frame.fullscreen(self.program)


class SkyGradientPlugin(Plugin):
    """The gradient sky: ``SkyGradientPlugin(settings=None, **fields)`` with :class:`SkyGradientSettings`;
    ``configure(**changes)`` changes any of them live (next frame)."""

    settings_class = SkyGradientSettings

    def build(self, app) -> None:
        app.graph.add_pass(SkyGradientPass(self))
