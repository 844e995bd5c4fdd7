"""SkyPlugin and its passes: the Preetham or the physical sky with sun disc, night and stars as the
scene's background; with the physical sky, its LUTs and the Sun's light from the same model."""
from __future__ import annotations

import numpy as np

from atmos.camera import Camera
from atmos.composition import composition
from atmos.graph import ComputePass, PassContext, RenderPass
from atmos.lighting import Sun
from atmos.gpu.uniforms import write_uniforms
from atmos.plugin import Plugin
import atmos.plugins.sky.sun_light as sun_light
from atmos.plugins.sky.aerial import AERIAL, AerialPerspectivePass, active
from atmos.plugins.sky.luts import (SKY_LUTS, AtmosphereLuts, atmosphere_defines, camera_altitude,
                                    set_atmosphere_uniforms, view_radius)
from atmos.plugins.sky.light import SkyLight
from atmos.plugins.sky.settings import SkySettings
from atmos.plugins.sky.shader import set_sky_uniforms, sky_defines
from atmos.render_core import COLOR, DEPTH


class SkyLutsPass(RenderPass):
    """Phase sky, before the sky pass: brings the physical sky's LUTs up to date (transmittance and
    multiple scattering when the atmosphere changes, the sky view when the sun's height or the
    camera's altitude does). Declares nothing with the Preetham model: culled."""
    name = "sky_luts"
    phase = "sky"

    def __init__(self, plugin):
        self.plugin = plugin

    def setup(self, builder) -> None:
        if self.plugin.settings.model != "physical":
            self.plugin._release_luts()          # back to Preetham: the LUTs go
            return
        builder.read(SKY_LUTS)
        builder.write(SKY_LUTS)

    def execute(self, frame: PassContext) -> None:
        view = frame.view
        frame.resource(SKY_LUTS).update(self.plugin.settings.atmosphere, camera_altitude(view.camera),
                                        float(view.sun.direction[1]))


class SkyPass(ComputePass):
    """Writes the sky into every pixel of ``color`` where nothing was drawn (depth 1; later passes draw
    over it), from the Sun resource: Preetham's formula, or the physical sky's sky-view LUT; one
    compute invocation per pixel (``sky/sky.comp``)."""
    name = "sky"
    phase = "sky"
    compute = "sky/sky.comp"
    reads = (DEPTH,)
    writes = (COLOR,)

    @property
    def physical(self) -> bool:
        return self.plugin.settings.model == "physical"

    def defines(self) -> dict:
        if self.physical:
            return {**sky_defines(), **atmosphere_defines(), "SKY_PHYSICAL": 1}
        return sky_defines()

    def setup_key(self) -> tuple:
        return (self.plugin.settings, self.reads, self.writes)

    def setup(self, builder) -> None:
        super().setup(builder)
        if self.physical:
            builder.read(SKY_LUTS)

    def execute(self, frame: PassContext) -> None:
        view, p = frame.view, self.program
        camera = view.camera
        settings = self.plugin.settings
        set_sky_uniforms(p, settings, view.sun.direction, view.sun.color, view.time,
                         camera.fov_y / max(1, view.size[1]))
        if self.physical:
            frame.resource(SKY_LUTS).bind(p)
            set_atmosphere_uniforms(p, settings.atmosphere)
            write_uniforms(p, view_r=view_radius(settings.atmosphere, camera))
        color = frame.image(COLOR)
        frame.dispatch(p, self.groups(color.size), textures={"scene_depth": DEPTH}, images={"color_image": color})


class SkyPlugin(Plugin):
    """The sky (passes "sky_luts" and "sky"): ``SkyPlugin(settings=None, **fields)`` with
    :class:`SkySettings`, e.g. ``SkyPlugin(model="physical")``; ``configure(**changes)`` changes any
    of them live (next frame), the atmosphere field by field (``configure(atmosphere={"mie_g": 0.7})``).

    With ``model="physical"`` the system ``sky_light`` (after DaylightPlugin's ``daylight``) writes
    ``Sun.color`` and ``Sun.ambient`` from the same atmosphere (:mod:`atmos.plugins.sky.sun_light`),
    and ``Sun.color_by_altitude`` (the sun's colour at any altitude: the clouds take it at theirs),
    and it publishes :class:`~atmos.plugins.sky.light.SkyLight`, the sky's light as other effects see
    it (a FogPlugin's ``color_from="sky"`` takes its horizon from it)."""

    settings_class = SkySettings

    def __init__(self, settings: SkySettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.luts: AtmosphereLuts | None = None
        self.gpu = self.graph = self.composition = None
        self.aerial_pass: AerialPerspectivePass | None = None
        self.light: SkyLight | None = None    # the sky's light as other effects see it (published)

    def build(self, app) -> None:
        self.gpu = app.gpu
        self.graph = app.graph
        self.composition = composition(app)
        app.graph.add_pass(SkyLutsPass(self))
        app.graph.add_pass(SkyPass(self))
        self.composition.backgrounds.add(SkyPass.name)      # it writes every pixel after the depth clear
        self.aerial_pass = AerialPerspectivePass(self)
        app.graph.add_pass(self.aerial_pass)
        app.graph.import_resource(SKY_LUTS, self._luts)
        self.light = SkyLight(self)
        app.insert_resource(self.light)
        self._read_distance()

    def configure(self, **changes) -> SkySettings:
        settings = super().configure(**changes)
        self._read_distance()
        return settings

    def _read_distance(self) -> None:
        """The aerial perspective reads the clouds' own distance and the local media (atmos.composition)
        while it is on."""
        if self.composition is None:
            return
        for readers in (self.composition.readers, self.composition.media_readers):
            if active(self.settings):
                readers.add(AERIAL)
            else:
                readers.discard(AERIAL)

    def finish(self, app) -> None:
        labels = {s.label for s in app.schedule.systems}
        for stage, after in (("update", "daylight"), ("startup", "daylight_start")):
            app.add_system(self.sun_light, stage, label=f"sky_light{'_start' if stage == 'startup' else ''}",
                           after=(after,) if after in labels else ())

    def cleanup(self, app) -> None:
        self._release_luts()
        if self.composition is not None:
            self.composition.backgrounds.discard(SkyPass.name)
            self.composition.readers.discard(AERIAL)
            self.composition.media_readers.discard(AERIAL)
        self._drop_sun_path(app.get_resource(Sun))

    def _luts(self) -> AtmosphereLuts:
        """The imported "sky_luts" (resolved only in frames that draw the physical sky): made on the
        first such frame, released when the model goes back to Preetham."""
        if self.luts is None:
            self.luts = AtmosphereLuts(self.gpu)
        return self.luts

    def _release_luts(self) -> None:
        if self.luts is not None:
            self.luts.release()
            self.luts = None

    def sun_light(self, app) -> None:
        """System: with the physical sky, the Sun's colour and ambient for its direction and the
        camera's altitude, and its colour by altitude (nothing with the Preetham model)."""
        s = self.settings
        sun = app.get_resource(Sun)
        if s.model != "physical":
            self._drop_sun_path(sun)
            return
        if sun is None:
            sun = Sun()
            app.insert_resource(sun)
        camera = app.get_resource(Camera)
        altitude = camera_altitude(camera) if camera is not None else 0.0
        sun.color = tuple(sun_light.sun_color(sun.direction, altitude, s.atmosphere))
        sun.ambient = tuple(sun_light.sky_ambient(sun.direction, altitude, s.atmosphere, s.night))
        sun.color_by_altitude = self.sun_color_at
        sun_light.bake_ahead()              # one node next to those in use: no frame bakes several

    def sun_color_at(self, direction, altitudes) -> np.ndarray:
        """``Sun.color_by_altitude`` of the physical sky: (n, 3) the sun's colour at ``altitudes`` (n,) m."""
        return sun_light.sun_color(direction, altitudes, self.settings.atmosphere)

    def _drop_sun_path(self, sun: Sun | None) -> None:
        if sun is not None and sun.color_by_altitude == self.sun_color_at:
            sun.color_by_altitude = None
