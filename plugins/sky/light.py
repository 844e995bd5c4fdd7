"""SkyLight: the sky's light as other effects see it (the resource a SkyPlugin publishes).

``horizon(sun, altitude, n)``: the sky's radiance just above the horizon (``ELEVATION``) at ``n``
azimuths round it, ``2π i / n`` from −z toward +x as :meth:`atmos.lighting.Sun.from_angles` counts
them: the Preetham sky (its turbidity and scale) or the physical one (its atmosphere, seen from
``altitude``), computed once per change of its inputs. ``aerial``: whether the aerial perspective
is on; ``declare_aerial``/``aerial_defines``/``set_aerial_uniforms``: what a pass that reads the
air's light (the light shafts' march) needs of it.
"""
from __future__ import annotations

import math

import numpy as np

import atmos.plugins.sky.radiance as radiance
from atmos.composition import CompositedElsewhere
from atmos.gpu.uniforms import write_uniforms
from atmos.plugins.sky.aerial import active
from atmos.plugins.sky.luts import SKY_LUTS, atmosphere_defines, set_atmosphere_uniforms, view_radius
from atmos.plugins.sky.sun_light import horizon_radiance

ELEVATION = math.radians(2.0)
HORIZON_SAMPLES = 32         # the azimuths its readers ask for (the fog's table; the ground's mean), one cache


def horizon_directions(n: int) -> np.ndarray:
    """(n, 3) unit directions ``ELEVATION`` above the horizon at azimuths 2π i / n."""
    a = 2.0 * np.pi * np.arange(n) / n
    c = math.cos(ELEVATION)
    return np.stack([np.sin(a) * c, np.full(n, math.sin(ELEVATION)), -np.cos(a) * c], -1)


def horizon_colors(sun, sky_settings, n: int, altitude: float = 0.0) -> np.ndarray:
    """(n, 3) float64 linear radiance of the horizon sky of ``sky_settings`` (a SkySettings) for ``sun``
    (an :class:`atmos.Sun`), seen from ``altitude`` (m; the physical sky)."""
    if sky_settings.model == "physical":
        return horizon_radiance(horizon_directions(n), sun.direction, altitude, sky_settings.atmosphere,
                                sky_settings.night)
    return radiance.sky_radiance(horizon_directions(n), np.asarray(sun.direction, np.float64),
                                 sky_settings.turbidity, sky_settings.scale, sky_settings.night)


class SkyLight(CompositedElsewhere):
    """See the module docstring; ``plugin`` is the SkyPlugin that publishes it. Another pass may composite
    the air's aerial perspective (:class:`atmos.composition.CompositedElsewhere`; ``declare_pixel``,
    ``pixel_defines``, ``use_pixel``: sky/aerial_pixel.glsl in that pass)."""

    def __init__(self, plugin):
        self._plugin = plugin
        self._key = self._table = None

    @property
    def settings(self):
        return self._plugin.settings

    def horizon(self, sun, altitude: float, n: int) -> np.ndarray:
        """(n, 3) float64 horizon radiance (module docstring); the last table again while its inputs hold."""
        settings = self.settings
        altitude = float(altitude) if settings.model == "physical" else 0.0
        key = (settings, tuple(np.asarray(sun.direction, np.float64)), altitude, int(n))
        if key != self._key:
            self._key, self._table = key, horizon_colors(sun, settings, n, altitude)
        return self._table

    def mean_horizon(self, sun, altitude: float) -> np.ndarray:
        """(3,) float64: :meth:`horizon` at HORIZON_SAMPLES azimuths, averaged round the horizon."""
        return self.horizon(sun, altitude, HORIZON_SAMPLES).mean(axis=0)

    @property
    def aerial(self) -> bool:
        """The aerial perspective is on (SkySettings.aerial_perspective with the physical model)."""
        return active(self.settings)

    @property
    def reads_cloud_distance(self) -> bool:
        """The aerial perspective hazes clouds by their own distance (atmos.composition)."""
        return self._plugin.composition is not None and self._plugin.composition.distance

    def declare_aerial(self, builder) -> None:
        """A pass that reads the air's light reads the sky's LUTs."""
        builder.read(SKY_LUTS)

    def aerial_defines(self) -> dict:
        return atmosphere_defines()

    def declare_pixel(self, builder) -> None:
        """A pass that composites the air itself (sky/aerial_pixel.glsl) reads the LUTs and fills the froxel volume."""
        self._plugin.aerial_pass.declare_pixel(builder)

    def pixel_defines(self) -> dict:
        """sky/aerial_pixel.glsl's variant (the atmosphere's defines, its steps, whether froxels)."""
        return self._plugin.aerial_pass.pixel_defines()

    def use_pixel(self, frame, program) -> list[int]:
        """Fill and bind what sky/aerial_pixel.glsl reads for ``program``; the units to :meth:`clear_pixel` after."""
        return self._plugin.aerial_pass.use_pixel(frame, program)

    def clear_pixel(self, units) -> None:
        self._plugin.aerial_pass.clear_sampler(units)

    def set_aerial_uniforms(self, frame, program) -> None:
        """The atmosphere's uniforms, its LUTs bound and the camera's radius (``view_r``)."""
        frame.resource(SKY_LUTS).bind(program)
        set_atmosphere_uniforms(program, self.settings.atmosphere)
        write_uniforms(program, view_r=view_radius(self.settings.atmosphere, frame.view.camera))
