"""CloudShadowSettings: the settings of the ground shadows, checked as a whole before any is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, bool_field, num_field, vec_field


@dataclass(frozen=True)
class CloudShadowSettings(CheckedSettings):
    """Where the cloud layer is and how dark its shadow is (world units are metres, y is up; all live).

    Cell ``(i, j, k)`` has its centre at ``((origin.x + i + 0.5)·cx, base_altitude + (j + 0.5)·cy,
    (origin.z + k + 0.5)·cz)`` with ``origin`` the :class:`~atmos.plugins.clouds.weather.VolumeOrigin`
    (in cells) and ``(cx, cy, cz)`` the ``cell_size``.
    """

    base_altitude: float | None = num_field(None, doc="world height of the bottom of the simulation volume "
                                            "(None: the simulation's ``CloudSettings.base_altitude``)",
                                            optional=True)
    cell_size: tuple | None = vec_field(None, 3, "positive", "(cx, cy, cz) metres per cell (None: the "
                                        "simulation's ``CloudSettings.cell_size``)", optional=True)
    sigma: float | None = num_field(None, 0.0, doc="extinction per cell length at density 1 (None: "
                                    "``CloudSettings.sigma``)", optional=True)
    strength: float = num_field(1.0, 0.0, doc="k in ``exp(−sigma·k·sum)`` (0: no shadows, > 1: darker than "
                                "physical)")
    direct_fraction: float = num_field(0.75, 0.0, 1.0, "the part of a surface's light that is direct sunlight "
                                       "(what a cloud can block); the rest (sky ambient) is kept")
    horizon_fade: float = num_field(0.1, 0.0, 1.0, "shadows fade in while the sun's height (the y of its unit "
                                    "direction, sin of its elevation) rises from 0 to this, so a grazing sun, "
                                    "whose projection runs far, fades them out, and a sun at or below the "
                                    "horizon casts none", lo_open=True)
    far_field: bool = bool_field(True, "beyond the volume, shadows continue with the cover of a "
                                 "CloudFarFieldPlugin when the App has one (its column's optical depth × "
                                 "``strength``, with the volume's complementary edge weight), so they have no "
                                 "edge where the volume ends")
