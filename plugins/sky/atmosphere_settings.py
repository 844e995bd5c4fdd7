"""AtmosphereSettings: the medium of the physical sky (``SkySettings.model = "physical"``), checked as a whole."""
from __future__ import annotations

import math
from dataclasses import dataclass

from atmos.checks import CheckedSettings, num_field, vec_field

@dataclass(frozen=True)
class AtmosphereSettings(CheckedSettings):
    """A planet's atmosphere after Hillaire 2020 (the defaults: Earth, Bruneton & Hillaire's values).
    Lengths in metres, coefficients in 1/m per colour channel (linear sRGB red, green, blue). All
    live (next frame)."""

    planet_radius: float = num_field(6360e3, 1e3, 1e9, "m: the ground's distance from the planet's centre")
    atmosphere_height: float = num_field(100e3, 100.0, 1e7, "m; the top is at planet_radius + this")
    rayleigh_scattering: tuple = vec_field((5.802e-6, 13.558e-6, 33.1e-6), 3, "non-negative", "Rayleigh "
                                           "scattering, at most 0.01")
    rayleigh_scale_height: float = num_field(8000.0, 1.0, 1e7, "m: the Rayleigh density is exp(-h / this)")
    mie_scattering: tuple = vec_field((3.996e-6, 3.996e-6, 3.996e-6), 3, "non-negative", "Mie (aerosol) "
                                      "scattering, at most 0.01")
    mie_absorption: tuple = vec_field((0.444e-6, 0.444e-6, 0.444e-6), 3, "non-negative", "Mie (aerosol) "
                                      "absorption, at most 0.01")
    mie_scale_height: float = num_field(1200.0, 1.0, 1e7, "m: the Mie density is exp(-h / this)")
    mie_g: float = num_field(0.8, -0.99, 0.99, "asymmetry of the Mie Henyey–Greenstein phase")
    ozone_absorption: tuple = vec_field((0.650e-6, 1.881e-6, 0.085e-6), 3, "non-negative", "ozone absorption "
                                        "(a tent profile), at most 0.01")
    ozone_altitude: float = num_field(25e3, 0.0, 1e7, "m: the ozone density is 1 here")
    ozone_width: float = num_field(30e3, 1.0, 1e7, "m: the ozone density falls to 0 this / 2 above and below "
                                   "ozone_altitude")
    ground_albedo: tuple = vec_field((0.3, 0.3, 0.3), 3, "non-negative", "the Lambertian ground's albedo, each "
                                     "at most 1")
    sun_color: tuple = vec_field((1.033, 1.079, 1.124), 3, "non-negative", "the sun's colour above the "
                                 "atmosphere in Sun.color units (the default puts a noon sun, 68° high, where "
                                 ":func:`atmos.lighting.sky_light` puts it, so exposure and the scenes lit by "
                                 "Sun.color stay as they were)")
    sun_intensity: float = num_field(4.0 * math.pi, 0.0, 1e6, "the irradiance one unit of Sun.color stands for, "
                                     "as :class:`~atmos.plugins.clouds.CloudSettings` ``.sun_intensity`` (the "
                                     "same 4π: the sky and the clouds see one sun)")
    multiple_scattering: float = num_field(1.0, 0.0, 1.0, "the weight of Hillaire's multiple-scattering term "
                                           "(1: the model; 0: single scattering only)")

    def __post_init__(self):
        """The declared checks, then the upper bounds of ground_albedo and of the coefficients."""
        given = {name: getattr(self, name) for name in ("ground_albedo", "rayleigh_scattering", "mie_scattering",
                                                        "mie_absorption", "ozone_absorption")}  # for the messages
        super().__post_init__()
        o = type(self).__name__
        if max(self.ground_albedo) > 1.0:
            raise ValueError(f"{o}.ground_albedo must be 3 numbers in [0, 1], got {given['ground_albedo']!r}")
        for name in ("rayleigh_scattering", "mie_scattering", "mie_absorption", "ozone_absorption"):
            if max(getattr(self, name)) > 1e-2:
                raise ValueError(f"{o}.{name} must be 3 coefficients in [0, 0.01] per metre (Earth's are "
                                 f"~1e-6..1e-5), got {given[name]!r}")

    @property
    def top_radius(self) -> float:
        return self.planet_radius + self.atmosphere_height
