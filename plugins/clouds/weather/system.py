"""The weather rules (thesis sec. 4.3.3.5) as a function of (world, settings, rng, dt), and the App plugin.

One call of :func:`step_weather` applies, in this order:

* rule 3 — every ellipsoid ages by ``dt``; one whose ``age >= lifetime`` is removed;
* rule 4 — every ellipsoid moves by ``(wind + wind_field(x, z) + its personal offset) · dt``;
* rule 5 — one whose centre left the region boundings (volume box + ``region_margin``) is removed;
* rule 1 — below ``cloud_density``: ``min(density_adaption, target − count)`` new random
  ellipsoids are created at random positions inside the region boundings;
* rule 2 — above ``cloud_density``: ``min(density_adaption, count − target)`` are removed,
  chosen by position and age (farthest outside the visible volume first, then the oldest
  relative to its lifetime, then the lowest entity id);
* and the shrink of sec. 4.3.3.4 ("reduce the size of an ellipsoid shortly before the lifetime
  ends"): ``scale = clip((lifetime − age) / shrink_time, 0, 1)``.

All randomness comes from the caller's ``numpy.random.Generator`` and ellipsoids are visited in
entity-id order, so a run is reproducible from the generator's seed.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from operator import itemgetter

import numpy as np

from atmos.checks import check_choice, check_int
from atmos.plugin import Plugin
from atmos.plugins.clouds.weather.components import MAX_CELLS, NCOLS, Ellipsoid, VolumeOrigin, ellipsoid_problem
from atmos.plugins.clouds.weather.settings import WeatherSettings


@dataclass(slots=True)
class StepReport:
    """What one :func:`step_weather` call did."""
    died: int = 0      # rule 3: lifetime over
    left: int = 0      # rule 5: left the region boundings
    created: int = 0   # rule 1
    removed: int = 0   # rule 2: above the target density
    rejected: int = 0  # invalid ellipsoids (NaN, inf, radius <= 0, ...) removed with a warning
    count: int = 0     # ellipsoids after the step


def wind_field_at(field, lo, hi, x, z) -> np.ndarray:
    """Bilinear interpolation of a (gx, gz, 2) wind grid laid over the rectangle ``lo..hi`` (x, z).

    Grid value [i, k] sits at the centre of grid cell (i, k): ``lo + (i + 0.5)·(hi − lo)/g``;
    positions outside the cell centres take the nearest edge value (clamped). Returns (n, 2).
    """
    f = np.asarray(field, dtype=np.float64)
    gx, gz = f.shape[0], f.shape[1]
    x = np.asarray(x, dtype=np.float64)
    z = np.asarray(z, dtype=np.float64)
    u = np.clip((x - lo[0]) / (hi[0] - lo[0]) * gx - 0.5, 0.0, gx - 1)
    v = np.clip((z - lo[1]) / (hi[1] - lo[1]) * gz - 0.5, 0.0, gz - 1)
    i0 = np.minimum(np.floor(u).astype(np.int64), max(gx - 2, 0))
    k0 = np.minimum(np.floor(v).astype(np.int64), max(gz - 2, 0))
    i1 = np.minimum(i0 + 1, gx - 1)
    k1 = np.minimum(k0 + 1, gz - 1)
    fu = (u - i0)[:, None]
    fv = (v - k0)[:, None]
    return ((1 - fu) * (1 - fv) * f[i0, k0] + fu * (1 - fv) * f[i1, k0]
            + (1 - fu) * fv * f[i0, k1] + fu * fv * f[i1, k1])


def _sorted_ellipsoids(world) -> list:
    return sorted(world.get_component(Ellipsoid), key=itemgetter(0))


def _shrink(e: Ellipsoid, shrink_time: float) -> None:
    e.scale = 1.0 if shrink_time <= 0 else min(1.0, max(0.0, (e.lifetime - e.age) / shrink_time))


def step_weather(world, settings: WeatherSettings, rng: np.random.Generator, dt: float = 1.0,
                 origin=(0.0, 0.0, 0.0)) -> StepReport:
    """Apply the five rules once to the :class:`Ellipsoid` entities of ``world``.

    ``dt``: seconds this step advances (ages and wind displacements scale with it; the count
    rules are per step). ``origin``: world position (cells) of the simulation volume's cell
    (0, 0, 0), i.e. where the viewer's volume is now; the region boundings are around it.
    """
    if not isinstance(settings, WeatherSettings):
        raise ValueError(f"step_weather needs a WeatherSettings, got {type(settings).__name__}")
    if not (isinstance(dt, (int, float, np.floating)) and math.isfinite(dt) and dt >= 0):
        raise ValueError(f"dt must be a finite number >= 0 (seconds), got {dt!r}")
    origin = np.asarray(origin, dtype=np.float64)
    if origin.shape != (3,) or not np.isfinite(origin).all():
        raise ValueError(f"origin must be three finite numbers (x, y, z) in cells, got {origin!r}")
    report = StepReport()
    lo, hi = settings.region_bounds(origin)
    pairs = _reject_invalid(world, _sorted_ellipsoids(world), report)
    doomed = []

    # rule 3: age; remove at the end of the lifetime
    alive = []
    for entity, e in pairs:
        e.age += dt
        if e.age >= e.lifetime:
            doomed.append(entity)
            report.died += 1
        else:
            alive.append((entity, e))

    # rule 4: move by the wind (+ the 8×8 field) and the ellipsoid's personal offset
    if alive:
        wx, wy, wz = settings.wind
        if settings.wind_field is not None:
            xs = np.fromiter((e.x for _, e in alive), np.float64, len(alive))
            zs = np.fromiter((e.z for _, e in alive), np.float64, len(alive))
            local = wind_field_at(settings.wind_field, (lo[0], lo[2]), (hi[0], hi[2]), xs, zs).tolist()
        else:
            local = None
        lx, ly, lz = lo.tolist()
        hx, hy, hz = hi.tolist()
        kept = []
        for index, (entity, e) in enumerate(alive):
            fx, fz = local[index] if local is not None else (0.0, 0.0)
            e.vx = wx + fx + e.drift_x
            e.vy = wy
            e.vz = wz + fz + e.drift_z
            e.x += e.vx * dt
            e.y += e.vy * dt
            e.z += e.vz * dt
            # rule 5: out of the region boundings -> removed
            if not (lx <= e.x <= hx and ly <= e.y <= hy and lz <= e.z <= hz):
                doomed.append(entity)
                report.left += 1
            else:
                kept.append((entity, e))
        alive = kept

    for entity in doomed:
        world.delete_entity(entity, immediate=True)

    target = settings.cloud_density
    count = len(alive)
    if count < target:
        # rule 1: add at most density_adaption new random ellipsoids
        k = min(settings.density_adaption, target - count)
        for e in _random_ellipsoids(settings, rng, k, lo, hi, origin):
            world.create_entity(e)
        report.created = k
    elif count > target:
        # rule 2: remove at most density_adaption, chosen by position (outside the view first) and age
        k = min(settings.density_adaption, count - target)
        ids = np.array([entity for entity, _ in alive])
        vlo = origin
        vhi = origin + np.asarray(settings.volume_shape, np.float64)
        pos = np.array([(e.x, e.z) for _, e in alive])
        outside = np.hypot(np.maximum(0, np.maximum(vlo[0] - pos[:, 0], pos[:, 0] - vhi[0])),
                           np.maximum(0, np.maximum(vlo[2] - pos[:, 1], pos[:, 1] - vhi[2])))
        ageing = np.array([e.age / e.lifetime for _, e in alive])
        order = np.lexsort((ids, -ageing, -outside))[:k]
        for entity in ids[order].tolist():
            world.delete_entity(entity, immediate=True)
        report.removed = k

    # shrink shortly before the lifetime ends
    for _, e in world.get_component(Ellipsoid):
        _shrink(e, settings.shrink_time)
    report.count = len(world.get_component(Ellipsoid))
    return report


def _all_valid(pairs: list) -> bool:
    """The fast path of :func:`_reject_invalid`: every field finite, radii and lifetimes > 0, within
    MAX_CELLS (vectorized; False sends the step through the per-ellipsoid check)."""
    try:
        a = np.array([(e.x, e.y, e.z, e.rx, e.ry, e.rz, e.lifetime, e.yaw, e.age, e.drift_x, e.drift_z,
                       e.vx, e.vy, e.vz, e.scale) for _, e in pairs], dtype=np.float64)
    except (TypeError, ValueError):
        return False
    return bool(np.isfinite(a).all() and (a[:, 3:7] > 0).all() and (np.abs(a[:, :6]) <= MAX_CELLS).all())


def _reject_invalid(world, pairs: list, report: StepReport) -> list:
    """``pairs`` without the invalid ellipsoids (:func:`ellipsoid_problem`), which are deleted from
    ``world`` with one RuntimeWarning each naming the entity: one bad entity never stops the others
    or later steps."""
    if not pairs or _all_valid(pairs):
        return pairs
    kept = []
    for entity, e in pairs:
        problem = ellipsoid_problem(e)
        if problem is None:
            kept.append((entity, e))
            continue
        world.delete_entity(entity, immediate=True)
        report.rejected += 1
        warnings.warn(f"weather: removed invalid ellipsoid entity {entity} ({problem}); create ellipsoids "
                      f"with atmos.plugins.clouds.weather.add_ellipsoid to have them checked", RuntimeWarning, stacklevel=3)
    return kept


def _random_ellipsoids(settings: WeatherSettings, rng: np.random.Generator, k: int, lo, hi, origin) -> list:
    """``k`` new ellipsoids, uniformly inside the region boundings (rule 1); one rng call."""
    if k <= 0:
        return []
    u = rng.random((k, 10))
    s = lambda col: 2.0 * u[:, col] - 1.0  # uniform in [-1, 1)
    ny = settings.volume_shape[1]
    x = lo[0] + u[:, 0] * (hi[0] - lo[0])
    z = lo[2] + u[:, 1] * (hi[2] - lo[2])
    y = origin[1] + (settings.altitude + settings.altitude_variance * s(2)) * ny
    rx = settings.cloud_size + settings.cloud_size_variance * s(3)
    rz = settings.cloud_size + settings.cloud_size_variance * s(4)
    ry = settings.vertical_scale * 0.5 * (rx + rz)
    yaw = u[:, 5] * (2.0 * math.pi)
    life = settings.lifetime + settings.lifetime_variance * s(6)
    dx = settings.wind_variance * s(7)
    dz = settings.wind_variance * s(8)
    out = []
    for i in range(k):
        e = Ellipsoid(x=float(x[i]), y=float(y[i]), z=float(z[i]), rx=float(rx[i]), ry=float(ry[i]),
                      rz=float(rz[i]), yaw=float(yaw[i]), age=0.0, lifetime=float(life[i]),
                      drift_x=float(dx[i]), drift_z=float(dz[i]))
        _shrink(e, settings.shrink_time)
        out.append(e)
    return out


def ellipsoid_array(world, origin=(0.0, 0.0, 0.0)) -> np.ndarray:
    """The world's ellipsoids as an (n, 8) float32 array for :meth:`RegionVolume.render`.

    Columns ``(x, y, z, yaw, rx, ry, rz, 0)``: centre relative to ``origin`` (subtracted in
    float64, so far-flown worlds keep their precision), radii multiplied by the shrink scale.
    Ellipsoids that are not finite numbers in float32 are left out (the next :func:`step_weather`
    removes them with a warning).
    """
    pairs = _sorted_ellipsoids(world)
    a = np.zeros((len(pairs), NCOLS), np.float64)
    for i, (_, e) in enumerate(pairs):
        a[i, :7] = (e.x, e.y, e.z, e.yaw, e.rx * e.scale, e.ry * e.scale, e.rz * e.scale)
    a[:, 0:3] -= np.asarray(origin, dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        a = a.astype(np.float32)
    finite = np.isfinite(a).all(axis=1)
    return a if finite.all() else a[finite]


class WeatherPlugin(Plugin):
    """Weather ellipsoids for an App: the rules as the ``simulate`` system ``"weather"`` and, with a
    GPU, the region volume re-rendered after them by the ``simulate`` system ``"weather_region"``.

    ``WeatherPlugin(settings=None, *, seed=0, dtype="f4", **fields)`` with :class:`WeatherSettings`;
    ``configure(**changes)`` changes them live (the next step reads them; ``volume_shape`` is fixed).
    ``seed`` (the rules' random generator) and ``dtype`` (the region volume's texture format) are
    how the plugin starts, not settings. Resources: ``VolumeOrigin`` (move it with the viewer; one
    already inserted is kept) and, with a GPU, the ``RegionVolume`` (its ``.texture`` is what the
    automaton stage reads; order it ``after="weather_region"``).
    """

    settings_class = WeatherSettings

    def __init__(self, settings: WeatherSettings | None = None, *, seed: int = 0, dtype: str = "f4", **fields):
        super().__init__(settings, **fields)
        self.rng = np.random.default_rng(check_int("WeatherPlugin", "seed", seed, 0, 2**63 - 1))
        self.dtype = check_choice("WeatherPlugin", "dtype", dtype, ("f4", "f2"))
        self.region = None
        self.last_report = StepReport()

    def build(self, app) -> None:
        from atmos.plugins.clouds.weather.region import RegionVolume

        if app.get_resource(VolumeOrigin) is None:
            app.insert_resource(VolumeOrigin())
        app.add_system(self._step, "simulate", label="weather")
        if app.gpu is not None:
            self.region = RegionVolume(app.gpu, self.settings.volume_shape, dtype=self.dtype)
            app.insert_resource(self.region)
            app.add_system(self._render_region, "simulate", label="weather_region", after="weather")

    def _step(self, app) -> None:
        origin = app.resource(VolumeOrigin).as_tuple()
        self.last_report = step_weather(app.world, self.settings, self.rng, app.clock.step, origin)

    def _render_region(self, app) -> None:
        origin = app.resource(VolumeOrigin).as_tuple()
        self.region.render(ellipsoid_array(app.world, origin))

    def cleanup(self, app) -> None:
        if self.region is not None:
            self.region.release()
            self.region = None
