"""AtmosphereSettings: the medium of the physical sky (``SkySettings.model = "physical"``), checked as a whole."""
from __future__ import annotations

import math
from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_num, check_vec

_OWNER = "AtmosphereSettings"


@dataclass(frozen=True)
class AtmosphereSettings(CheckedSettings):
    """A planet's atmosphere after Hillaire 2020 (the defaults: Earth, Bruneton & Hillaire's values).
    Lengths in metres, coefficients in 1/m per colour channel (linear sRGB red, green, blue).

    ``planet_radius``, ``atmosphere_height`` (the top is at planet_radius + atmosphere_height);
    Rayleigh scattering ``rayleigh_scattering`` with density ``exp(-h / rayleigh_scale_height)``;
    Mie (aerosols) ``mie_scattering`` + ``mie_absorption`` with ``exp(-h / mie_scale_height)`` and a
    Henyey–Greenstein phase of asymmetry ``mie_g``; ozone absorption ``ozone_absorption`` with a
    tent profile, 1 at ``ozone_altitude`` falling to 0 ``ozone_width / 2`` above and below; a
    Lambertian ground of ``ground_albedo`` (0..1); ``sun_color``: the sun's colour above the
    atmosphere in ``Sun.color`` units (the default puts a noon sun, 68° high, where
    :func:`atmos.lighting.sky_light` puts it, so exposure and the scenes lit by ``Sun.color`` stay
    as they were); ``sun_intensity``: the irradiance one unit of ``Sun.color`` stands for, as
    :class:`~atmos.plugins.clouds.CloudSettings` ``.sun_intensity`` (the same 4π: the sky and the
    clouds see one sun); ``multiple_scattering``: the weight of Hillaire's multiple-scattering term
    (1: the model; 0: single scattering only). All live (next frame)."""

    planet_radius: float = 6360e3
    atmosphere_height: float = 100e3
    rayleigh_scattering: tuple = (5.802e-6, 13.558e-6, 33.1e-6)
    rayleigh_scale_height: float = 8000.0
    mie_scattering: tuple = (3.996e-6, 3.996e-6, 3.996e-6)
    mie_absorption: tuple = (0.444e-6, 0.444e-6, 0.444e-6)
    mie_scale_height: float = 1200.0
    mie_g: float = 0.8
    ozone_absorption: tuple = (0.650e-6, 1.881e-6, 0.085e-6)
    ozone_altitude: float = 25e3
    ozone_width: float = 30e3
    ground_albedo: tuple = (0.3, 0.3, 0.3)
    sun_color: tuple = (1.033, 1.079, 1.124)
    sun_intensity: float = 4.0 * math.pi
    multiple_scattering: float = 1.0

    def __post_init__(self):
        o = _OWNER
        checked = dict(
            planet_radius=check_num(o, "planet_radius", self.planet_radius, 1e3, 1e9),
            atmosphere_height=check_num(o, "atmosphere_height", self.atmosphere_height, 100.0, 1e7),
            rayleigh_scattering=check_vec(o, "rayleigh_scattering", self.rayleigh_scattering, 3, "non-negative"),
            rayleigh_scale_height=check_num(o, "rayleigh_scale_height", self.rayleigh_scale_height, 1.0, 1e7),
            mie_scattering=check_vec(o, "mie_scattering", self.mie_scattering, 3, "non-negative"),
            mie_absorption=check_vec(o, "mie_absorption", self.mie_absorption, 3, "non-negative"),
            mie_scale_height=check_num(o, "mie_scale_height", self.mie_scale_height, 1.0, 1e7),
            mie_g=check_num(o, "mie_g", self.mie_g, -0.99, 0.99),
            ozone_absorption=check_vec(o, "ozone_absorption", self.ozone_absorption, 3, "non-negative"),
            ozone_altitude=check_num(o, "ozone_altitude", self.ozone_altitude, 0.0, 1e7),
            ozone_width=check_num(o, "ozone_width", self.ozone_width, 1.0, 1e7),
            ground_albedo=check_vec(o, "ground_albedo", self.ground_albedo, 3, "non-negative"),
            sun_color=check_vec(o, "sun_color", self.sun_color, 3, "non-negative"),
            sun_intensity=check_num(o, "sun_intensity", self.sun_intensity, 0.0, 1e6),
            multiple_scattering=check_num(o, "multiple_scattering", self.multiple_scattering, 0.0, 1.0),
        )
        if max(checked["ground_albedo"]) > 1.0:
            raise ValueError(f"{o}.ground_albedo must be 3 numbers in [0, 1], got {self.ground_albedo!r}")
        for name in ("rayleigh_scattering", "mie_scattering", "mie_absorption", "ozone_absorption"):
            if max(checked[name]) > 1e-2:
                raise ValueError(f"{o}.{name} must be 3 coefficients in [0, 0.01] per metre (Earth's are "
                                 f"~1e-6..1e-5), got {getattr(self, name)!r}")
        self.store(checked)

    @property
    def top_radius(self) -> float:
        return self.planet_radius + self.atmosphere_height
