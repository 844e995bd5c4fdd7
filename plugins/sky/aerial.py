"""The physical sky's aerial perspective: the pass "aerial_perspective" (phase media).

With ``SkySettings.model = "physical"`` and ``aerial_perspective`` on, every pixel that shows the scene
(terrain, ground, meshes) gets the sunlight the air between it and the camera scatters toward the
camera, and loses what that air absorbs and scatters away: ``C → L + T·C``, both marched through the
sky's own atmosphere and LUTs (``shaders/sky/aerial.frag``; float64:
:func:`atmos.plugins.sky.atmosphere.aerial_perspective`). Distant hills turn the sky's blue by day and
its orange at sunset, with no fog colour to choose. Clouds that give the media passes their own distance
(:mod:`atmos.composition`) are hazed by it. It runs after the other media passes (local fog lies in
front of the surfaces it covers; the atmosphere spans the whole ray). Culled with Preetham or off.
"""
from __future__ import annotations

from atmos.composition import CLOUD_DISTANCE
from atmos.graph import FullscreenPass, PassContext
from atmos.camera import set_camera_uniforms
from atmos.lighting import unit_sun
from atmos.plugins.sky.luts import SKY_LUTS, atmosphere_defines, set_atmosphere_uniforms, view_radius
from atmos.render_core import COLOR, DEPTH

AERIAL = "aerial_perspective"


def active(settings) -> bool:
    """Whether the sky's settings ask for the aerial perspective (it needs the physical model)."""
    return settings.model == "physical" and settings.aerial_perspective


class AerialPerspectivePass(FullscreenPass):
    """See the module docstring; ``plugin`` is the SkyPlugin (its settings, composition and graph)."""
    name = AERIAL
    phase = "media"
    fragment = "sky/aerial.frag"

    @property
    def after(self) -> tuple[str, ...]:
        """Every other media pass of the graph (the fog, volumetric fog, a game's haze)."""
        return tuple(p.name for p in self.plugin.graph.passes if p.phase == self.phase and p is not self)

    def clouds(self) -> bool:
        return self.plugin.composition.distance

    def defines(self) -> dict:
        return {**atmosphere_defines(), "AERIAL_STEPS": self.plugin.settings.aerial_steps,
                "AERIAL_CLOUDS": int(self.clouds())}

    def setup(self, builder) -> None:
        if not active(self.plugin.settings):
            return                              # declares nothing: culled, nothing allocated
        builder.read(DEPTH)
        builder.read(COLOR)                     # blends onto it
        builder.write(COLOR)
        builder.read(SKY_LUTS)
        if self.clouds():
            builder.read(CLOUD_DISTANCE)

    def execute(self, frame: PassContext) -> None:
        view, p = frame.view, self.program
        settings = self.plugin.settings
        frame.framebuffer(color=[COLOR]).use()
        frame.blend_transmittance()
        frame.resource(DEPTH).use(0)
        if frame.declares(CLOUD_DISTANCE):
            frame.resource(CLOUD_DISTANCE).use(2)
        frame.resource(SKY_LUTS).use()
        set_camera_uniforms(p, view.camera, view.aspect)
        set_atmosphere_uniforms(p, settings.atmosphere)
        sun = unit_sun(view.sun.direction)
        p["sun_dir"].value = tuple(float(v) for v in sun)
        p["view_r"].value = view_radius(settings.atmosphere, view.camera)
        frame.fullscreen(p)
