"""ECS components of the weather layer (thesis sec. 4.3.3.3 and 4.3.3.5).

One entity per weather ellipsoid, carrying one :class:`Ellipsoid`. The rules mutate the component
in place every step; entities are created and deleted only by the rules that demand it (creation
toward the target density, death at the lifetime, leaving the region, removal above the target).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from atmos.checks import check_num

#: Columns of an ellipsoid array handed to :class:`RegionVolume.render` and :func:`region_volume`.
COLUMNS = ("x", "y", "z", "yaw", "rx", "ry", "rz", "pad")
NCOLS = len(COLUMNS)


def check_ellipsoid_array(ellipsoids) -> np.ndarray:
    """The array as float32 (n, 8); ValueError naming what is allowed."""
    a = np.asarray(ellipsoids, dtype=np.float32)
    if a.size == 0:
        return np.zeros((0, NCOLS), np.float32)
    if a.ndim != 2 or a.shape[1] != NCOLS:
        raise ValueError(f"ellipsoids must be an (n, {NCOLS}) array with columns {COLUMNS}; got shape {a.shape}")
    if not np.isfinite(a).all():
        raise ValueError("ellipsoids must hold finite numbers; the array holds NaN or inf")
    return np.ascontiguousarray(a)


@dataclass(slots=True)
class Ellipsoid:
    """A weather ellipsoid: where clouds may form (sec. 4.3.2/4.3.3).

    ``x, y, z``: centre in world cells (the simulation volume's cell (0, 0, 0) covers
    ``[origin, origin + 1)``), y is height. ``rx, ry, rz``: full-size radii in cells along the
    ellipsoid's own axes. ``yaw``: orientation, radians around the height axis (the thesis stores
    "two components for scaling in x and y" and "an orientation attribute", so one angle suffices);
    the local x axis points along world (cos yaw, 0, sin yaw). ``age`` and ``lifetime`` in seconds;
    the ellipsoid dies in the first step where ``age >= lifetime``. ``drift_x, drift_z``: the
    ellipsoid's constant personal wind offset (cells/s). ``vx, vy, vz``: the velocity applied in the
    last step (wind + offset). ``scale``: the shrink factor of the radii, 1 until ``shrink_time``
    before the end of the lifetime, then falling linearly to 0.
    """
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    rx: float = 1.0
    ry: float = 1.0
    rz: float = 1.0
    yaw: float = 0.0
    age: float = 0.0
    lifetime: float = 1.0
    drift_x: float = 0.0
    drift_z: float = 0.0
    vx: float = 0.0
    vy: float = 0.0
    vz: float = 0.0
    scale: float = 1.0

    @property
    def remaining(self) -> float:
        """Seconds of lifetime left."""
        return self.lifetime - self.age


#: Largest radius and distance from the volume (in cells) an ellipsoid may have: far beyond any volume,
#: small enough that positions relative to the viewer and radii stay finite in float32 on the GPU.
MAX_CELLS = 1e9
_POSITIVE = ("rx", "ry", "rz", "lifetime")


def ellipsoid_problem(e: Ellipsoid) -> str | None:
    """What is wrong with ``e`` (None when nothing is): every field a finite number, |value| <= MAX_CELLS
    for the position and radii, radii and lifetime > 0."""
    for f in fields(Ellipsoid):
        value = getattr(e, f.name)
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
                or not math.isfinite(value):
            return f"Ellipsoid.{f.name} must be a finite number, got {value!r}"
        if f.name in _POSITIVE and not value > 0:
            return f"Ellipsoid.{f.name} must be > 0, got {value!r}"
        if f.name in ("x", "y", "z", "rx", "ry", "rz") and abs(value) > MAX_CELLS:
            return f"Ellipsoid.{f.name} must be within ±{MAX_CELLS:g} cells, got {value!r}"
    return None


def add_ellipsoid(world, **fields_) -> int:
    """Create a weather ellipsoid entity in ``world`` (an App's ``app.world``) from :class:`Ellipsoid`
    fields, checked first: a ValueError names the field and what is allowed, and nothing is created."""
    try:
        e = Ellipsoid(**fields_)
    except TypeError:
        known = ", ".join(f.name for f in fields(Ellipsoid))
        raise ValueError(f"add_ellipsoid takes Ellipsoid fields ({known}), got {', '.join(sorted(fields_))}") from None
    problem = ellipsoid_problem(e)
    if problem is not None:
        raise ValueError(f"add_ellipsoid: {problem}")
    return world.create_entity(e)


@dataclass(slots=True)
class VolumeOrigin:
    """World position (in cells) of the simulation volume's cell (0, 0, 0); moves with the viewer.

    An App resource of :class:`atmos.plugins.clouds.weather.WeatherPlugin`: game code moves it, the
    weather rules put the region boundings around it, and the region volume is rendered at it.
    Every assignment is checked: finite numbers (a ValueError names ``VolumeOrigin.field``).
    """
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0

    def __setattr__(self, name: str, value) -> None:
        object.__setattr__(self, name, check_num("VolumeOrigin", name, value) if name in "xyz" else value)

    def as_tuple(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)
