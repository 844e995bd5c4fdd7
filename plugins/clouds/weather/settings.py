"""WeatherSettings: the user-facing settings of the weather ellipsoids (thesis sec. 4.3.3.4).

Units: positions and sizes are in cells of the simulation volume; times are in seconds of
simulation time (with ``dt = 1`` a "second" is one simulation step, as in the thesis, where the
lifetime is decreased by one per step); wind speeds are in cells per second.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, check_shape, int_field, num_field, vec_field

#: Upper bound of ``cloud_density`` (ellipsoids are ECS entities; the rules run in Python).
MAX_CLOUD_DENSITY = 100_000
_OWNER = "WeatherSettings"


@dataclass(frozen=True, eq=False)
class WeatherSettings(CheckedSettings):
    """Settings of the ellipsoid weather (sec. 4.3.3.4) and of the region-volume probabilities
    (thesis Appendix A; R is the region-volume value in [0, 1]). Units: the module docstring.

    Every field is live (read when the next step begins) but ``volume_shape``, which sizes the
    GPU volumes: it is FIXED. Two fields are checked by hand (not in the list below):

    ``volume_shape`` = (64, 32, 64): (nx, ny, nz) cells of the simulation volume (three positive ints).
    ``wind_field`` = None: or an array of shape (gx, gz, 2) (the thesis's 8×8 grid: (8, 8, 2)) of
    horizontal wind (wx, wz) per cell of a grid laid over the region boundings, indexed [x cell,
    z cell], interpolated bilinearly at the ellipsoid centre (clamped at the edges) and added to
    ``wind``; kept as a read-only float64 array.
    """
    cloud_density: int = int_field(100, 0, MAX_CLOUD_DENSITY, "target number of ellipsoids (in the whole "
                                   "region, not only in view)")
    density_adaption: int = int_field(2, 1, MAX_CLOUD_DENSITY, "at most this many ellipsoids are created, and "
                                      "at most this many removed for being above the target, in one step "
                                      "(deaths and leaving the region are not limited by it)")
    cloud_size: float = num_field(6.0, 0.0, doc="horizontal radius in cells: the x and z radii are drawn "
                                  "independently, uniformly from cloud_size ± cloud_size_variance", lo_open=True)
    cloud_size_variance: float = num_field(2.0, 0.0, doc="cells, the radii's largest aberration from cloud_size; "
                                           "< cloud_size (no radius 0 or negative)")
    vertical_scale: float = num_field(0.5, 0.0, doc="vertical radius = this × the mean of the two horizontal "
                                      "radii", lo_open=True)
    altitude: float = num_field(0.5, 0.0, 1.0, "centre height as a fraction of the volume height (ny), drawn "
                                "uniformly from altitude ± altitude_variance")
    altitude_variance: float = num_field(0.15, 0.0, 1.0, "the centre height's largest aberration from altitude "
                                         "(a fraction of ny)")
    lifetime: float = num_field(60.0, 0.0, doc="seconds, drawn uniformly from lifetime ± lifetime_variance",
                                lo_open=True)
    lifetime_variance: float = num_field(20.0, 0.0, doc="seconds, the lifetime's largest aberration; < lifetime "
                                         "(every lifetime positive)")
    shrink_time: float = num_field(5.0, 0.0, doc="the radii fall linearly from full size to 0 over the last this "
                                   "many seconds of the lifetime (0: no shrinking)")
    region_margin: float = num_field(16.0, 0.0, doc="cells: the region boundings are the volume box grown by this "
                                     "on every side (horizontally and vertically); ellipsoids live in it and die "
                                     "when their centre leaves it")
    volume_shape: tuple = (64, 32, 64)
    wind: tuple = vec_field((1.0, 0.0, 0.0), 3, doc="(wx, wy, wz) cells per second, the same for every ellipsoid")
    wind_variance: float = num_field(0.1, 0.0, doc="cells per second: each ellipsoid gets a constant personal "
                                     "offset drawn uniformly from [-this, this] on x and on z at creation")
    wind_field: object = None
    hum_scale: float = num_field(0.1, 0.0, 1.0, "p_hum = hum_scale × R")
    act_scale: float = num_field(0.001, 0.0, 1.0, "p_act = act_scale × R")
    ext_scale: float = num_field(0.1, 0.0, 1.0, "p_ext = ext_scale × (1 − R)")
    vanish_threshold: float = num_field(0.001, 0.0, 1.0, "p_ext = 1 where R <= this (cells outside every "
                                        "ellipsoid lose their cloud)")

    FIXED = ("volume_shape",)

    def __post_init__(self):
        """Check every field; a ValueError names ``WeatherSettings.field``, the value and what is allowed."""
        given = self.cloud_size_variance, self.lifetime_variance     # as given, for the messages
        super().__post_init__()
        o = _OWNER
        if self.cloud_size_variance >= self.cloud_size:
            raise ValueError(f"{o}.cloud_size_variance must be >= 0 and < cloud_size ({self.cloud_size}) "
                             f"so that no radius is 0 or negative, got {given[0]!r}")
        if self.lifetime_variance >= self.lifetime:
            raise ValueError(f"{o}.lifetime_variance must be >= 0 and < lifetime ({self.lifetime}) "
                             f"so that every lifetime is positive, got {given[1]!r}")
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
        self.store(dict(volume_shape=check_shape(self.volume_shape, f"{o}.volume_shape"), wind_field=wind_field))

    # -- derived -------------------------------------------------------------------------
    def region_bounds(self, origin=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) corners of the region boundings for a volume whose cell (0, 0, 0) is at ``origin``."""
        o = np.asarray(origin, dtype=np.float64)
        m = self.region_margin
        return o - m, o + np.asarray(self.volume_shape, dtype=np.float64) + m
