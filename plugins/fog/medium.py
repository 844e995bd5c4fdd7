"""FogMedium: the fog as other effects see it (the resource a FogPlugin publishes): what a pass that
shadows or mixes the fog's in-scattered light (the light shafts' march) needs of it, without
reaching into the fog's modules."""
from __future__ import annotations

from atmos.plugins.fog.post import set_fog_uniforms
from atmos.plugins.fog.settings import MODES
from atmos.plugins.fog.sky_color import SAMPLES


class FogMedium:
    """``plugin`` is the FogPlugin that publishes it."""

    def __init__(self, plugin):
        self._plugin = plugin
        self._compositor = None         # () -> bool: another pass composites the fog this frame

    def composite_elsewhere(self, wants) -> None:
        """Let another pass composite the fog (the light shafts' froxel apply, exactly as the fog's own
        pass would, with what it takes away in one write) while ``wants()`` is true; the fog's own pass
        is then culled. None gives the fog back to its pass."""
        self._compositor = wants

    @property
    def composited_elsewhere(self) -> bool:
        """Whether another pass composites the fog this frame (:meth:`composite_elsewhere`)."""
        return self._compositor is not None and self._compositor()

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
