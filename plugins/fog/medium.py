"""FogMedium: the fog as other effects see it (the resource a FogPlugin publishes): what a pass that
shadows or mixes the fog's in-scattered light (the light shafts' march) needs of it, without
reaching into the fog's modules."""
from __future__ import annotations

from atmos.composition import CompositedElsewhere
from atmos.plugins.fog.post import set_fog_uniforms
from atmos.plugins.fog.settings import MODES
from atmos.plugins.fog.sky_color import SAMPLES


class FogMedium(CompositedElsewhere):
    """``plugin`` is the FogPlugin that publishes it; another pass may composite the fog
    (:class:`atmos.composition.CompositedElsewhere`, fog/over.glsl: exactly as the fog's own pass)."""

    def __init__(self, plugin):
        self._plugin = plugin

    @property
    def settings(self):
        return self._plugin.settings

    @property
    def reads_cloud_distance(self) -> bool:
        """The fog hazes clouds by their own distance (atmos.composition)."""
        composition = self._plugin.composition
        return composition is not None and composition.distance

    def defines(self) -> dict:
        """The ``fog/factor.glsl`` and ``fog/color.glsl`` variant of these settings, its turbulence
        evaluated procedurally (the fog's noise volumes stay the fog's)."""
        s = self.settings
        return dict(FOG_MODE=MODES[s.mode], FOG_OCTAVES=s.octaves, FOG_PROCEDURAL=1,
                    FOG_SKY_COLOR=int(s.color_from == "sky"), FOG_HORIZON_SAMPLES=SAMPLES,
                    FOG_SUN=int(s.sun_scattering > 0))

    def set_uniforms(self, program, view) -> None:
        """The factor's and the colour's uniforms at this SceneView's time, sun and camera."""
        s = self.settings
        set_fog_uniforms(program, s, view.time + s.time_offset, self._plugin.sky_table(view), view.sun)
