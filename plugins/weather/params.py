"""WeatherParams: the user-facing parameters of the weather ellipsoids (thesis sec. 4.3.3.4).

Units: positions and sizes are in cells of the simulation volume; times are in seconds of
simulation time (with ``dt = 1`` a "second" is one simulation step, as in the thesis, where the
lifetime is decreased by one per step); wind speeds are in cells per second.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from atmos.checks import check_shape, is_int

#: Upper bound of ``cloud_density`` (ellipsoids are ECS entities; the rules run in Python).
MAX_CLOUD_DENSITY = 100_000


def _is_real(value) -> bool:
    return isinstance(value, (numbers.Real, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


@dataclass(slots=True, eq=False)
class WeatherParams:
    """Parameters of the ellipsoid weather (sec. 4.3.3.4) and of the region-volume probabilities.

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

    def __post_init__(self):
        self.validate()

    def validate(self) -> "WeatherParams":
        """Check every field; raise ValueError naming the field and what is allowed. Returns self."""
        def real(name, lo=None, hi=None, lo_open=False):
            value = getattr(self, name)
            if not _is_real(value) or not math.isfinite(float(value)):
                raise ValueError(f"WeatherParams.{name} must be a finite number, got {value!r}")
            value = float(value)
            if lo is not None and (value < lo or (lo_open and value == lo)):
                raise ValueError(f"WeatherParams.{name} must be {'>' if lo_open else '>='} {lo}"
                                 + (f" and <= {hi}" if hi is not None else "") + f", got {value!r}")
            if hi is not None and value > hi:
                raise ValueError(f"WeatherParams.{name} must be <= {hi}, got {value!r}")
            object.__setattr__(self, name, value)
            return value

        def integer(name, lo, hi):
            value = getattr(self, name)
            if not is_int(value) or not lo <= int(value) <= hi:
                raise ValueError(f"WeatherParams.{name} must be an int in [{lo}, {hi}], got {value!r}")
            object.__setattr__(self, name, int(value))

        integer("cloud_density", 0, MAX_CLOUD_DENSITY)
        integer("density_adaption", 1, MAX_CLOUD_DENSITY)
        size = real("cloud_size", 0.0, lo_open=True)
        real("cloud_size_variance", 0.0)
        if self.cloud_size_variance >= size:
            raise ValueError(f"WeatherParams.cloud_size_variance must be >= 0 and < cloud_size ({size}) "
                             f"so that no radius is 0 or negative, got {self.cloud_size_variance!r}")
        real("vertical_scale", 0.0, lo_open=True)
        real("altitude", 0.0, 1.0)
        real("altitude_variance", 0.0, 1.0)
        life = real("lifetime", 0.0, lo_open=True)
        real("lifetime_variance", 0.0)
        if self.lifetime_variance >= life:
            raise ValueError(f"WeatherParams.lifetime_variance must be >= 0 and < lifetime ({life}) "
                             f"so that every lifetime is positive, got {self.lifetime_variance!r}")
        real("shrink_time", 0.0)
        real("region_margin", 0.0)
        object.__setattr__(self, "volume_shape", check_shape(self.volume_shape, "WeatherParams.volume_shape"))
        wind = self.wind
        try:
            wind = tuple(wind)
        except TypeError:
            wind = None
        if (wind is None or len(wind) != 3 or not all(_is_real(w) for w in wind)
                or not all(math.isfinite(float(w)) for w in wind)):
            raise ValueError(f"WeatherParams.wind must be three finite numbers (wx, wy, wz) in cells "
                             f"per second, got {self.wind!r}")
        object.__setattr__(self, "wind", tuple(float(w) for w in wind))
        real("wind_variance", 0.0)
        if self.wind_field is not None:
            try:
                f = np.array(self.wind_field, dtype=np.float64)
            except (TypeError, ValueError):
                raise ValueError(f"WeatherParams.wind_field must be None or a numeric array of shape "
                                 f"(gx, gz, 2), e.g. (8, 8, 2); got {type(self.wind_field).__name__}") from None
            if f.ndim != 3 or f.shape[2] != 2 or f.shape[0] < 1 or f.shape[1] < 1:
                raise ValueError(f"WeatherParams.wind_field must be None or an array of shape (gx, gz, 2), "
                                 f"e.g. (8, 8, 2); got shape {f.shape}")
            if not np.isfinite(f).all():
                raise ValueError("WeatherParams.wind_field must hold finite numbers; it holds NaN or inf")
            f.setflags(write=False)
            object.__setattr__(self, "wind_field", f)
        real("hum_scale", 0.0, 1.0)
        real("act_scale", 0.0, 1.0)
        real("ext_scale", 0.0, 1.0)
        real("vanish_threshold", 0.0, 1.0)
        return self

    # -- derived -------------------------------------------------------------------------
    def region_bounds(self, origin=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) corners of the region boundings for a volume whose cell (0, 0, 0) is at ``origin``."""
        o = np.asarray(origin, dtype=np.float64)
        m = self.region_margin
        return o - m, o + np.asarray(self.volume_shape, dtype=np.float64) + m
