"""CloudShadowsPlugin: darkens the scene's surfaces where the cloud layer blocks the sun (thesis 7.3.1)."""
from __future__ import annotations

from atmos.graph import ComputePass, PassContext
from atmos.lighting import unit_sun
from atmos.plugin import Plugin
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.shadows.settings import CloudShadowSettings
from atmos.plugins.clouds.shadows.shadow_map import (SHADOW_MAP, SHADOW_SPACE, cloud_extinctions, shadow_map_pass,
                                                     use_shadow_map)
from atmos.plugins.clouds.volume.column import column_uniforms
from atmos.plugins.clouds.volume.sets import CLOUD_SETS, FAR_FIELD, CloudSets
from atmos.render_core import COLOR, DEPTH
from atmos.gpu.uniforms import write_uniforms


def direct_weight(sun_direction, sun_color, settings) -> float:
    """How much of the light shadows can take away: ``direct_fraction`` × smoothstep(0,
    ``horizon_fade``, sun height), and 0 when the sun has no colour (night) or no direction."""
    s = unit_sun(sun_direction)
    if s is None or not max(map(float, sun_color)) > 0.0:
        return 0.0
    x = min(max(float(s[1]) / settings.horizon_fade, 0.0), 1.0)
    return settings.direct_fraction * x * x * (3.0 - 2.0 * x)


def cloud_layout(sim, settings: CloudShadowSettings) -> CloudLayout:
    """The volume's world placement (``layout()`` of CloudSets or the CloudSimulation), with ``settings.base_altitude``
    and ``settings.cell_size`` where they are set."""
    return sim.layout(settings.base_altitude, settings.cell_size)


class CloudShadowsPass(ComputePass):
    """Multiplies "color" in place by the shadow factor where "depth" has geometry (one compute
    invocation per pixel, alpha kept): the optical depth read from the cloud shadow map, or (``exact``,
    or settings placing the shadows apart from the volume: ``base_altitude``/``cell_size``) summed from
    the density maps per pixel."""
    name = "cloud_shadows"
    phase = "shadows"
    compute = "clouds/shadows/shadow.comp"
    reads = (COLOR, DEPTH, CLOUD_SETS)
    writes = (COLOR,)
    exact = False               # True: always the column sums (benchmarks, references)

    def far_field(self) -> bool:
        """Whether the shadows continue with a far field's cover (one is imported, ``settings.far_field``)."""
        return self.plugin.settings.far_field and self.plugin.graph.imports(FAR_FIELD)

    def uses_map(self) -> bool:
        """Whether the optical depth comes from the shadow map (baked for the volume's own placement)."""
        params = self.plugin.settings
        return not self.exact and params.base_altitude is None and params.cell_size is None

    def defines(self) -> dict:
        if self.uses_map():
            return {}
        return {"CLOUD_SHADOW_EXACT": 1, **({"CLOUD_FAR_FIELD": 1} if self.far_field() else {})}

    def setup_key(self) -> tuple:
        return (self.plugin.settings, self.exact, self.plugin.graph.imports(FAR_FIELD), self.reads, self.writes)

    def setup(self, builder) -> None:
        super().setup(builder)
        if self.uses_map():
            builder.read(SHADOW_MAP)
            builder.read(SHADOW_SPACE)
            if self.far_field():
                builder.read(FAR_FIELD)      # its column optical depth (the map holds its columns)
        elif self.far_field():
            builder.read(FAR_FIELD)

    def execute(self, frame: PassContext) -> None:
        view, p = frame.view, self.program
        params = self.plugin.settings
        sun = view.sun
        weight = direct_weight(sun.direction, sun.color, params)
        if weight <= 0.0 or params.strength == 0.0:
            return                                  # no direct light to take away: nothing to do
        sim: CloudSets = frame.resource(CLOUD_SETS)
        layout = cloud_layout(sim, params)
        own_sigma, field_tau = cloud_extinctions(frame)
        sigma = own_sigma if params.sigma is None else params.sigma
        write_uniforms(p, weight=weight)
        if frame.declares(SHADOW_MAP):
            use_shadow_map(frame, p, sigma * params.strength, field_tau * params.strength)
        else:
            layer = frame.resource(FAR_FIELD) if frame.declares(FAR_FIELD) else None
            if layer is not None:               # first: its measure dispatches programs of its own
                layer.prepare(view, sim)
            column_uniforms(p, sim, layout, sigma * params.strength)
            if layer is not None:
                layer.use(p, view, sim)
                write_uniforms(p, field_column_tau=field_tau * params.strength)
        frame.dispatch(p, self.groups(frame.image(COLOR).size), textures={"scene_depth": DEPTH},
                       images={"color_image": COLOR})


class CloudShadowsPlugin(Plugin):
    """Ground shadows of the clouds of a CloudsPlugin (phase shadows: over the ground and terrain,
    under the clouds themselves): ``CloudShadowsPlugin(settings=None, **fields)`` with
    :class:`CloudShadowSettings`; ``configure(**changes)`` changes any of them live (next frame)."""

    settings_class = CloudShadowSettings

    def build(self, app) -> None:
        if app.graph is None:
            raise ValueError("CloudShadowsPlugin needs an App with a GPU context (App(gpu))")
        self.graph = app.graph
        shadow_map_pass(app.graph)
        app.graph.add_pass(CloudShadowsPass(self))
