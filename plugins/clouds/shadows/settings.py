"""CloudShadowSettings: the settings of the ground shadows, checked as a whole before any is used (all live)."""
from __future__ import annotations

from dataclasses import dataclass

from atmos.checks import CheckedSettings, check_bool, check_num, check_vec

_OWNER = "CloudShadowSettings"


@dataclass(frozen=True)
class CloudShadowSettings(CheckedSettings):
    """Where the cloud layer is and how dark its shadow is (world units are metres, y is up).

    ``base_altitude``: world height of the bottom of the simulation volume (None: the simulation's
    ``CloudSettings.base_altitude``); cell ``(i, j, k)`` has
    its centre at ``((origin.x + i + 0.5)·cx, base_altitude + (j + 0.5)·cy, (origin.z + k + 0.5)·cz)``
    with ``origin`` the :class:`~atmos.plugins.clouds.weather.VolumeOrigin` (in cells).
    ``cell_size``: (cx, cy, cz) metres per cell; ``None`` takes the simulation's ``CloudSettings.cell_size``.
    ``sigma``: extinction per cell length at density 1; ``None`` takes ``CloudSettings.sigma``.
    ``strength``: k in ``exp(−sigma·k·sum)`` (0: no shadows, > 1: darker than physical).
    ``direct_fraction``: the part of a surface's light that is direct sunlight (what a cloud can
    block); the rest (sky ambient) is kept. ``horizon_fade``: shadows fade in while the sun's height
    (the y of its unit direction, sin of its elevation) rises from 0 to this, so a grazing sun, whose
    projection runs far, fades them out, and a sun at or below the horizon casts none.
    ``far_field``: beyond the volume, shadows continue with the cover of a CloudFarFieldPlugin when
    the App has one (its column's optical depth × ``strength``, with the volume's complementary edge
    weight), so they have no edge where the volume ends.
    """

    base_altitude: float | None = None
    cell_size: tuple | None = None
    sigma: float | None = None
    strength: float = 1.0
    direct_fraction: float = 0.75
    horizon_fade: float = 0.1
    far_field: bool = True

    def __post_init__(self):
        o = _OWNER
        checked = dict(
            base_altitude=check_num(o, "base_altitude", self.base_altitude, optional=True),
            cell_size=check_vec(o, "cell_size", self.cell_size, 3, "positive", optional=True),
            sigma=check_num(o, "sigma", self.sigma, 0.0, optional=True),
            strength=check_num(o, "strength", self.strength, 0.0),
            direct_fraction=check_num(o, "direct_fraction", self.direct_fraction, 0.0, 1.0),
            horizon_fade=check_num(o, "horizon_fade", self.horizon_fade, 0.0, 1.0, lo_open=True),
            far_field=check_bool(o, "far_field", self.far_field),
        )
        self.store(checked)
