"""WeatherSettings: the user-facing settings of the weather ellipsoids (thesis sec. 4.3.3.4).

Units: positions and sizes are in cells of the simulation volume; times are in seconds of
simulation time (with ``dt = 1`` a "second" is one simulation step, as in the thesis, where the
lifetime is decreased by one per step); wind speeds are in cells per second.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, check_int, check_num, check_shape, check_vec

#: Upper bound of ``cloud_density`` (ellipsoids are ECS entities; the rules run in Python).
MAX_CLOUD_DENSITY = 100_000
_OWNER = "WeatherSettings"


@dataclass(frozen=True, eq=False)
class WeatherSettings(CheckedSettings):
    """Settings of the ellipsoid weather (sec. 4.3.3.4) and of the region-volume probabilities.

    Every field is live (read when the next step begins) but ``volume_shape``, which sizes the
    GPU volumes: it is FIXED.

    Ellipsoids
        ``cloud_density``: target number of ellipsoids (in the whole region, not only in view).
        ``density_adaption``: at most this many ellipsoids are created, and at most this many
        removed for being above the target, in one step (deaths and leaving the region are not
        limited by it).
        ``cloud_size`` / ``cloud_size_variance``: horizontal radius in cells, drawn uniformly from
        ``cloud_size ± cloud_size_variance`` (independently for the x and z radius; variance is
        the maximum aberration, so it may not exceed the size).
        ``vertical_scale``: vertical radius = ``vertical_scale`` × mean of the two horizontal radii.
        ``altitude`` / ``altitude_variance``: centre height as a fraction of the volume height
        (``ny``), drawn uniformly from ``altitude ± altitude_variance``.
        ``lifetime`` / ``lifetime_variance``: seconds, drawn uniformly from ``lifetime ± variance``.
        ``shrink_time``: the radii fall linearly from full size to 0 over the last ``shrink_time``
        seconds of the lifetime (0: no shrinking).
        ``region_margin``: the region boundings are the volume box grown by this many cells on
        every side (horizontally and vertically); ellipsoids live in it and die when their centre
        leaves it.
        ``volume_shape``: (nx, ny, nz) cells of the simulation volume.

    Wind
        ``wind``: (wx, wy, wz) cells per second, the same for every ellipsoid.
        ``wind_variance``: each ellipsoid gets a constant personal offset drawn uniformly from
        ``[-wind_variance, wind_variance]`` on x and on z at creation.
        ``wind_field``: ``None`` or an array of shape (gx, gz, 2) (the thesis's 8×8 grid: (8, 8, 2))
        of horizontal wind (wx, wz) per cell of a grid laid over the region boundings, indexed
        [x cell, z cell], interpolated bilinearly at the ellipsoid centre (clamped at the edges)
        and added to ``wind``.

    Probabilities (thesis Appendix A): ``p_hum = hum_scale × R``, ``p_act = act_scale × R``,
    ``p_ext = ext_scale × (1 − R)``, and ``p_ext = 1`` where ``R <= vanish_threshold`` (cells
    outside every ellipsoid lose their cloud), with R the region-volume value in [0, 1].
    """
    cloud_density: int = 100
    density_adaption: int = 2
    cloud_size: float = 6.0
    cloud_size_variance: float = 2.0
    vertical_scale: float = 0.5
    altitude: float = 0.5
    altitude_variance: float = 0.15
    lifetime: float = 60.0
    lifetime_variance: float = 20.0
    shrink_time: float = 5.0
    region_margin: float = 16.0
    volume_shape: tuple = (64, 32, 64)
    wind: tuple = (1.0, 0.0, 0.0)
    wind_variance: float = 0.1
    wind_field: object = None
    hum_scale: float = 0.1
    act_scale: float = 0.001
    ext_scale: float = 0.1
    vanish_threshold: float = 0.001

    FIXED = ("volume_shape",)

    def __post_init__(self):
        """Check every field; a ValueError names ``WeatherSettings.field``, the value and what is allowed."""
        o = _OWNER
        size = check_num(o, "cloud_size", self.cloud_size, 0.0, lo_open=True)
        variance = check_num(o, "cloud_size_variance", self.cloud_size_variance, 0.0)
        if variance >= size:
            raise ValueError(f"{o}.cloud_size_variance must be >= 0 and < cloud_size ({size}) "
                             f"so that no radius is 0 or negative, got {self.cloud_size_variance!r}")
        life = check_num(o, "lifetime", self.lifetime, 0.0, lo_open=True)
        life_variance = check_num(o, "lifetime_variance", self.lifetime_variance, 0.0)
        if life_variance >= life:
            raise ValueError(f"{o}.lifetime_variance must be >= 0 and < lifetime ({life}) "
                             f"so that every lifetime is positive, got {self.lifetime_variance!r}")
        wind_field = self.wind_field
        if wind_field is not None:
            try:
                f = np.array(wind_field, dtype=np.float64)
            except (TypeError, ValueError):
                raise ValueError(f"{o}.wind_field must be None or a numeric array of shape "
                                 f"(gx, gz, 2), e.g. (8, 8, 2); got {type(wind_field).__name__}") from None
            if f.ndim != 3 or f.shape[2] != 2 or f.shape[0] < 1 or f.shape[1] < 1:
                raise ValueError(f"{o}.wind_field must be None or an array of shape (gx, gz, 2), "
                                 f"e.g. (8, 8, 2); got shape {f.shape}")
            if not np.isfinite(f).all():
                raise ValueError(f"{o}.wind_field must hold finite numbers; it holds NaN or inf")
            f.setflags(write=False)
            wind_field = f
        self.store(dict(
            cloud_density=check_int(o, "cloud_density", self.cloud_density, 0, MAX_CLOUD_DENSITY),
            density_adaption=check_int(o, "density_adaption", self.density_adaption, 1, MAX_CLOUD_DENSITY),
            cloud_size=size, cloud_size_variance=variance,
            vertical_scale=check_num(o, "vertical_scale", self.vertical_scale, 0.0, lo_open=True),
            altitude=check_num(o, "altitude", self.altitude, 0.0, 1.0),
            altitude_variance=check_num(o, "altitude_variance", self.altitude_variance, 0.0, 1.0),
            lifetime=life, lifetime_variance=life_variance,
            shrink_time=check_num(o, "shrink_time", self.shrink_time, 0.0),
            region_margin=check_num(o, "region_margin", self.region_margin, 0.0),
            volume_shape=check_shape(self.volume_shape, f"{o}.volume_shape"),
            wind=check_vec(o, "wind", self.wind, 3),
            wind_variance=check_num(o, "wind_variance", self.wind_variance, 0.0),
            wind_field=wind_field,
            hum_scale=check_num(o, "hum_scale", self.hum_scale, 0.0, 1.0),
            act_scale=check_num(o, "act_scale", self.act_scale, 0.0, 1.0),
            ext_scale=check_num(o, "ext_scale", self.ext_scale, 0.0, 1.0),
            vanish_threshold=check_num(o, "vanish_threshold", self.vanish_threshold, 0.0, 1.0),
        ))

    # -- derived -------------------------------------------------------------------------
    def region_bounds(self, origin=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) corners of the region boundings for a volume whose cell (0, 0, 0) is at ``origin``."""
        o = np.asarray(origin, dtype=np.float64)
        m = self.region_margin
        return o - m, o + np.asarray(self.volume_shape, dtype=np.float64) + m
