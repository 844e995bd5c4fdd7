"""Collision helpers for games: rays, segments and overlaps in float64 numpy (no GL).

A ray is ``(origin, direction)``; the direction is normalised, so ``Hit.distance`` is in world units.
The nearest hit within ``max_distance`` is a :class:`Hit`, a miss is None; :func:`segment` tests the
segment from ``a`` to ``b`` (a ray toward b cut at |b − a|). Triangles are hit on both faces, edges
included. A ray starting inside a solid (box, sphere, at or under a height function or grid) hits at
distance 0, at its origin, normal −direction. Overlaps count touching and broadcast over leading axes.
Bad input is a ValueError naming the argument and what it may be. ``TerrainPlugin.raycast`` and
``atmos.plugins.mesh.raycast_instances`` build on these.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Hit", "bounds", "box_box", "closest_point_box", "height_normal", "ray_box", "ray_grid",
           "ray_heightfield", "ray_sphere", "ray_triangles", "segment", "sphere_box", "sphere_sphere"]

EDGE_SLACK = 1e-9          # barycentric slack: a ray through a shared edge or vertex cannot slip between triangles
PARALLEL = 1e-12           # |cos| between ray and triangle plane below which the ray counts as in the plane (no hit)
CHUNK = 65536              # triangles tested at once (bounds the temporary arrays)
MAX_SAMPLES = 10**8        # ray_heightfield: max_distance / step at most this


@dataclass(frozen=True, eq=False)
class Hit:
    """Where a ray meets something: ``distance`` along the unit ray from its origin, ``point`` (3,),
    the unit ``normal`` (3,) facing against the ray (n · direction <= 0) and, for triangle meshes and
    grids, the ``triangle``'s number (else None). Its arrays are read-only float64."""
    distance: float
    point: np.ndarray
    normal: np.ndarray
    triangle: int | None = None

    def __post_init__(self):
        for name in ("point", "normal"):
            a = np.array(getattr(self, name), np.float64) + 0.0       # + 0.0: no −0 components
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        object.__setattr__(self, "distance", float(self.distance))


# -- checks ------------------------------------------------------------------------------------------
def _show(value) -> str:
    if isinstance(value, np.ndarray) and value.size > 6:
        return f"an array of shape {value.shape}"
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _fail(fn: str, name: str, allowed: str, value):
    raise ValueError(f"{fn}: {name} must be {allowed}, got {_show(value)}")


def _floats(fn: str, name: str, value, allowed: str) -> np.ndarray:
    if isinstance(value, (str, bytes)):
        _fail(fn, name, allowed, value)
    try:
        a = np.asarray(value, np.float64)
    except (TypeError, ValueError):
        _fail(fn, name, allowed, value)
    if not np.isfinite(a).all():
        _fail(fn, name, allowed, value)
    return a


def _vec(fn: str, name: str, value, n: int = 3) -> np.ndarray:
    a = _floats(fn, name, value, f"{n} finite numbers")
    if a.shape != (n,):
        _fail(fn, name, f"{n} finite numbers", value)
    return a


def _points(fn: str, name: str, value) -> np.ndarray:
    a = _floats(fn, name, value, "finite numbers shaped (..., 3)")
    if a.ndim == 0 or a.shape[-1] != 3:
        _fail(fn, name, "finite numbers shaped (..., 3)", value)
    return a


def _radius(fn: str, name: str, value) -> np.ndarray:
    a = _floats(fn, name, value, "finite numbers >= 0")
    if (a < 0).any():
        _fail(fn, name, "finite numbers >= 0", value)
    return a


def _number(fn: str, name: str, value, allowed: str, ok) -> float:
    v = math.nan
    if not isinstance(value, (str, bytes, bool, np.bool_)):
        try:
            v = float(value)
        except (TypeError, ValueError):
            pass
    if math.isnan(v) or not ok(v):
        _fail(fn, name, allowed, value)
    return v


def _box(fn: str, lo, hi, lo_name: str = "box_min", hi_name: str = "box_max"):
    lo, hi = _points(fn, lo_name, lo), _points(fn, hi_name, hi)
    if (lo > hi).any():
        raise ValueError(f"{fn}: {hi_name} must be >= {lo_name} on every axis (extents >= 0), "
                         f"got {lo_name} {_show(lo)} and {hi_name} {_show(hi)}")
    return lo, hi


def check_ray(fn: str, origin, direction, max_distance, finite: bool = False):
    """(origin, unit direction, max_distance) as float64, or a ValueError naming ``fn`` and the argument."""
    o = _vec(fn, "origin", origin)
    d = _vec(fn, "direction", direction)
    scale = np.abs(d).max()
    if scale == 0:
        raise ValueError(f"{fn}: direction must be a non-zero 3-vector of finite numbers, got {_show(direction)}")
    d = d / scale
    d = d / np.linalg.norm(d)
    if finite:
        m = _number(fn, "max_distance", max_distance, "a finite number >= 0", lambda v: 0 <= v < math.inf)
    else:
        m = _number(fn, "max_distance", max_distance, "a number >= 0 (inf: unlimited)", lambda v: v >= 0)
    return o, d, m


def _inside(o, d) -> Hit:
    return Hit(0.0, o, -d)


# -- rays --------------------------------------------------------------------------------------------
def _slabs(o, d, lo, hi):
    """(t_near, t_far, axis of t_near) of the line o + t d through the box lo..hi (any dimension);
    an axis the ray does not move along bounds nothing when o is within it, else empties the range."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        inv = 1.0 / d
        t1, t2 = (lo - o) * inv, (hi - o) * inv
    flat = (d == 0) | ~np.isfinite(inv) | np.isnan(t1) | np.isnan(t2)
    within = (lo <= o) & (o <= hi)
    near = np.where(flat, np.where(within, -np.inf, np.inf), np.minimum(t1, t2))
    far = np.where(flat, np.where(within, np.inf, -np.inf), np.maximum(t1, t2))
    axis = int(np.argmax(near))
    return float(near[axis]), float(far.min()), axis


def ray_box(origin, direction, box_min, box_max, max_distance=math.inf) -> Hit | None:
    """The ray against the axis-aligned box ``box_min``..``box_max`` (slab method): the entry point with
    the face's outward normal; a ray along a face or edge touches it (a hit). From inside (or on the
    surface, leaving) it hits at distance 0 with normal −direction; ``triangle`` is None."""
    o, d, m = check_ray("ray_box", origin, direction, max_distance)
    lo, hi = _box("ray_box", box_min, box_max)
    if lo.shape != (3,) or hi.shape != (3,):
        _fail("ray_box", "box_min and box_max", "3 finite numbers each", (box_min, box_max))
    near, far, axis = _slabs(o, d, lo, hi)
    if near > far or far < 0:
        return None
    if near < 0:
        return _inside(o, d)
    if near > m:
        return None
    point = o + near * d
    point[axis] = lo[axis] if d[axis] > 0 else hi[axis]
    normal = np.zeros(3)
    normal[axis] = -np.sign(d[axis])
    return Hit(near, np.clip(point, lo, hi), normal)


def ray_sphere(origin, direction, centre, radius, max_distance=math.inf) -> Hit | None:
    """The ray against the sphere (``radius`` >= 0): the entry point, outward normal (a grazing ray
    touches it: a hit with the normal across the ray). From inside or on it: distance 0, −direction."""
    o, d, m = check_ray("ray_sphere", origin, direction, max_distance)
    c = _vec("ray_sphere", "centre", centre)
    r = _number("ray_sphere", "radius", radius, "a finite number >= 0", lambda v: 0 <= v < math.inf)
    oc = o - c
    b = float(oc @ d)
    cc = float(oc @ oc) - r * r
    if cc <= 0:
        return _inside(o, d)
    if b >= 0:                                   # outside and moving away
        return None
    q = oc - b * d                               # from the centre to the ray's closest point (accurate form)
    h = r * r - float(q @ q)
    if h < 0:
        return None
    t = cc / (-b + math.sqrt(h))                 # the near root, without cancellation
    if t > m:
        return None
    point = o + t * d
    normal = (point - c) / r if r > 0 else -d
    return Hit(t, point, normal / np.linalg.norm(normal))


def _triangles(fn: str, vertices, triangles) -> np.ndarray:
    if triangles is None:
        v = _floats(fn, "vertices", vertices, "finite numbers shaped (m, 3, 3) (triangles' corners), or (n, 3) "
                                              "with triangles (m, 3) indices")
        if v.ndim != 3 or v.shape[1:] != (3, 3):
            _fail(fn, "vertices", "shaped (m, 3, 3) (triangles' corners) when triangles is None, or (n, 3) "
                                  "with triangles (m, 3) indices", vertices)
        return v
    v = _floats(fn, "vertices", vertices, "finite numbers shaped (n, 3)")
    if v.ndim != 2 or v.shape[1] != 3:
        _fail(fn, "vertices", "finite numbers shaped (n, 3) (with triangles given)", vertices)
    i = np.asarray(triangles)
    if i.ndim != 2 or i.shape[1] != 3 or not (np.issubdtype(i.dtype, np.integer) or i.size == 0):
        _fail(fn, "triangles", "integer vertex numbers shaped (m, 3)", triangles)
    i = i.astype(np.int64)
    if i.size and (i.min() < 0 or i.max() >= len(v)):
        _fail(fn, "triangles", f"vertex numbers in 0..{len(v) - 1}", f"{i.min()}..{i.max()}")
    return v[i]


def _nearest_triangle(o, d, m: float, corners: np.ndarray, ids=None) -> Hit | None:
    """Möller–Trumbore against every triangle ``corners`` (k, 3, 3): the nearest hit with 0 <= t <= m;
    ``ids`` numbers them (default 0..k-1). Skips degenerate triangles and those the ray lies in."""
    best_t, best = math.inf, None
    for start in range(0, len(corners), CHUNK):
        c = corners[start:start + CHUNK]
        v0 = c[:, 0]
        e1, e2 = c[:, 1] - v0, c[:, 2] - v0
        n = np.cross(e1, e2)
        area = np.linalg.norm(n, axis=1)
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)                    # = −d · n
        ok = (np.abs(det) > PARALLEL * area) & (area > PARALLEL * np.linalg.norm(e1, axis=1)
                                                 * np.linalg.norm(e2, axis=1))
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / np.where(ok, det, 1.0)
        s = o - v0
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = (q @ d) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        hit = ok & (u >= -EDGE_SLACK) & (v >= -EDGE_SLACK) & (u + v <= 1 + EDGE_SLACK) & (t >= 0) & (t <= m)
        if hit.any():
            k = int(np.argmin(np.where(hit, t, np.inf)))
            if t[k] < best_t:
                normal = n[k] / area[k]
                best_t, best = float(t[k]), (start + k, normal if normal @ d <= 0 else -normal)
    if best is None:
        return None
    k, normal = best
    return Hit(best_t, o + best_t * d, normal, int(k if ids is None else ids[k]))


def ray_triangles(origin, direction, vertices, triangles=None, max_distance=math.inf) -> Hit | None:
    """The nearest hit on a triangle soup: ``vertices`` (n, 3) with ``triangles`` (m, 3) integer
    indices, or ``vertices`` (m, 3, 3) corners. Möller–Trumbore, vectorised over triangles; both faces,
    edges included (with 1e-9 barycentric slack); degenerate triangles and a ray lying in a triangle's
    plane do not hit. ``Hit.triangle``: its row; ties go to the lower row; the normal is the
    triangle's, turned against the ray."""
    o, d, m = check_ray("ray_triangles", origin, direction, max_distance)
    return _nearest_triangle(o, d, m, _triangles("ray_triangles", vertices, triangles))


def segment(test, a, b, *args, **kwargs):
    """``test`` (a ray function here, ``terrain.raycast``, ``functools.partial(raycast_instances,
    world)``...) along the segment from ``a`` to ``b``: the ray from a toward b with ``max_distance``
    |b − a|, the other arguments passed on; what it returns (distances from a), e.g.
    ``segment(ray_box, a, b, box_min, box_max)``."""
    a, b = _vec("segment", "a", a), _vec("segment", "b", b)
    length = float(np.linalg.norm(b - a))
    if not 0 < length < math.inf:
        raise ValueError(f"segment: a and b must be distinct finite points (the segment needs a direction), "
                         f"got a {_show(a)} and b {_show(b)}")
    if "max_distance" in kwargs:
        raise TypeError("segment: max_distance is the segment's length, do not pass it")
    return test(a, (b - a) / length, *args, max_distance=length, **kwargs)


# -- terrain -----------------------------------------------------------------------------------------
def _heights(fn: str, height, x, z) -> np.ndarray:
    try:
        y = np.broadcast_to(np.asarray(height(x, z), np.float64), np.shape(x))
    except (TypeError, ValueError) as error:
        raise ValueError(f"{fn}: height must be a numpy-vectorised callable height(x, z) -> y (arrays in, "
                         f"an array of their shape out): {error}") from None
    if not np.isfinite(y).all():
        k = int(np.flatnonzero(~np.isfinite(y.ravel()))[0])
        raise ValueError(f"{fn}: height(x, z) must return finite heights, got {y.ravel()[k]} at "
                         f"(x, z) = ({np.ravel(x)[k]:g}, {np.ravel(z)[k]:g})")
    return y


def height_normal(height, x, z, eps: float = 1e-3) -> np.ndarray:
    """Unit normals (..., 3) of the surface y = ``height(x, z)`` (numpy-vectorised) at (x, z), from
    central differences ``eps`` apart: normalise(−∂h/∂x, 1, −∂h/∂z)."""
    e = _number("height_normal", "eps", eps, "a finite number > 0", lambda v: 0 < v < math.inf)
    x = _floats("height_normal", "x", x, "finite numbers")
    z = _floats("height_normal", "z", z, "finite numbers")
    x, z = np.broadcast_arrays(x, z)
    dx = (_heights("height_normal", height, x + e, z) - _heights("height_normal", height, x - e, z)) / (2 * e)
    dz = (_heights("height_normal", height, x, z + e) - _heights("height_normal", height, x, z - e)) / (2 * e)
    n = np.stack([-dx, np.ones_like(dx), -dz], -1)
    return n / np.linalg.norm(n, axis=-1, keepdims=True)


def ray_heightfield(origin, direction, height, max_distance, step=1.0, tolerance=1e-6, eps=1e-3) -> Hit | None:
    """The ray against the ground y = ``height(x, z)`` (a numpy-vectorised callable): samples ``step``
    apart from the origin to ``max_distance`` (finite) find the first interval where the ray goes from
    above the ground to at or under it; bisection narrows it to ``tolerance`` along the ray, and the
    hit (linear within that bracket) is within ``tolerance`` of the crossing. A hill crossed between
    two samples above it (thinner than ``step`` along the ray) is missed. Normal:
    :func:`height_normal` (``eps``), which faces the ray at a crossing from above. ``triangle`` is None."""
    fn = "ray_heightfield"
    o, d, m = check_ray(fn, origin, direction, max_distance, finite=True)
    if not callable(height):
        _fail(fn, "height", "a numpy-vectorised callable height(x, z) -> y", height)
    step = _number(fn, "step", step, "a finite number > 0", lambda v: 0 < v < math.inf)
    tol = _number(fn, "tolerance", tolerance, "a finite number > 0", lambda v: 0 < v < math.inf)
    _number(fn, "eps", eps, "a finite number > 0", lambda v: 0 < v < math.inf)
    if m / step > MAX_SAMPLES:
        raise ValueError(f"{fn}: max_distance / step must be at most {MAX_SAMPLES:g} samples, got {m:g} / {step:g}")

    def above(t):                                # ray height over the ground at parameters t
        p = o + np.multiply.outer(t, d)
        return p[..., 1] - _heights(fn, height, p[..., 0], p[..., 2])

    count = int(m // step) + 1                   # samples at 0, step, ... (<= m), then m itself
    previous_t, previous_f = None, None
    for start in range(0, count, 4096):
        t = np.minimum(np.arange(start, min(start + 4096, count), dtype=np.float64) * step, m)
        if start + 4096 >= count and t[-1] < m:
            t = np.append(t, m)
        f = above(t)
        if previous_t is not None:
            t, f = np.append(previous_t, t), np.append(previous_f, f)
        under = np.flatnonzero(f <= 0)
        if len(under):
            k = int(under[0])
            if k == 0:                           # only the origin's sample can come first: inside
                return _inside(o, d)
            break
        previous_t, previous_f = t[-1:], f[-1:]
    else:
        return None
    ta, tb, fa, fb = float(t[k - 1]), float(t[k]), float(f[k - 1]), float(f[k])
    while tb - ta > tol:
        tm = 0.5 * (ta + tb)
        if not ta < tm < tb:                     # the bracket is as narrow as floats go
            break
        fm = float(above(np.array([tm]))[0])
        if fm > 0:
            ta, fa = tm, fm
        else:
            tb, fb = tm, fm
    hit_t = min(max(ta + (tb - ta) * fa / (fa - fb), ta), tb) if fa != fb else tb
    point = o + hit_t * d
    normal = height_normal(height, point[0], point[2], eps)
    return Hit(hit_t, point, normal)


def _grid_args(fn: str, heights, size, centre):
    h = _floats(fn, "heights", heights, "finite numbers shaped (nx, nz), nx and nz >= 2")
    if h.ndim != 2 or min(h.shape) < 2:
        _fail(fn, "heights", "finite numbers shaped (nx, nz), nx and nz >= 2", heights)
    s = _floats(fn, "size", size, "a finite number > 0 or two (x, z)")
    s = np.broadcast_to(s, 2) if s.ndim == 0 else s
    if s.shape != (2,) or not (s > 0).all():
        _fail(fn, "size", "a finite number > 0 or two (x, z)", size)
    c = _vec(fn, "centre", centre, 2)
    return h, s, c


def ray_grid(origin, direction, heights, size, max_distance=math.inf, centre=(0.0, 0.0)) -> Hit | None:
    """The ray against a regular triangulated grid, exactly: vertex (i, j) at x = centre_x − size_x/2 +
    i·size_x/(nx − 1), y = ``heights[i, j]``, z likewise with j (``size`` a number or (x, z)); cell
    (a, b) is the triangles (a, b) (a+1, b) (a, b+1) and (a, b+1) (a+1, b) (a+1, b+1), numbered
    2(a(nz − 1) + b) and that + 1 — :func:`atmos.plugins.terrain.heightfield`'s mesh. Only the
    cells the ray's xz projection crosses are tested. Outside its footprint there is nothing; over it,
    a ray starting at or under the surface hits at distance 0 (normal −direction, the triangle under it)."""
    fn = "ray_grid"
    o, d, m = check_ray(fn, origin, direction, max_distance)
    h, (sx, sz), (cx, cz) = _grid_args(fn, heights, size, centre)
    nx, nz = h.shape
    lo = np.array([cx - sx / 2, cz - sz / 2])
    cell = np.array([sx / (nx - 1), sz / (nz - 1)])
    hi = lo + cell * (np.array(h.shape) - 1)
    o2, d2 = o[[0, 2]], d[[0, 2]]
    near, far, _ = _slabs(o2, d2, lo, hi)
    t0, t1 = max(near, 0.0), min(far, m)
    if t0 > t1:
        return None
    span = np.array(h.shape) - 2

    def cells(t):
        xz = o2 + np.multiply.outer(t, d2)
        f = (xz - lo) / cell
        ab = np.clip(np.floor(f), 0, span).astype(np.int64)
        return ab, f - ab

    if near <= 0:                                # the origin is over the footprint: under the surface?
        (a, b), (fu, fw) = cells(np.array(0.0))
        if fu + fw <= 1:
            y, k = h[a, b] + fu * (h[a + 1, b] - h[a, b]) + fw * (h[a, b + 1] - h[a, b]), 0
        else:
            y, k = h[a + 1, b + 1] + (1 - fu) * (h[a, b + 1] - h[a + 1, b + 1]) \
                + (1 - fw) * (h[a + 1, b] - h[a + 1, b + 1]), 1
        if o[1] <= y:
            return Hit(0.0, o, -d, int(2 * (a * (nz - 1) + b) + k))
    t1 = t1 if math.isfinite(t1) else t0 + 1.0  # a vertical ray: its cell is anywhere along it
    ts = [np.array([t0, t1])]
    for axis in (0, 1):                          # where the ray crosses grid lines between t0 and t1
        if d2[axis] != 0:
            g0, g1 = sorted(((o2[axis] + t * d2[axis] - lo[axis]) / cell[axis] for t in (t0, t1)))
            lines = np.arange(math.ceil(g0), math.floor(g1) + 1, dtype=np.float64)
            ts.append((lo[axis] + lines * cell[axis] - o2[axis]) / d2[axis])
    ts = np.unique(np.clip(np.concatenate(ts), t0, t1))
    mids = 0.5 * (ts[:-1] + ts[1:]) if len(ts) > 1 else ts
    ab, _ = cells(mids)
    number = np.unique(ab[:, 0] * (nz - 1) + ab[:, 1])
    a, b = np.divmod(number, nz - 1)
    x0, x1 = lo[0] + a * cell[0], lo[0] + (a + 1) * cell[0]
    z0, z1 = lo[1] + b * cell[1], lo[1] + (b + 1) * cell[1]
    p00 = np.stack([x0, h[a, b], z0], -1)
    p10 = np.stack([x1, h[a + 1, b], z0], -1)
    p01 = np.stack([x0, h[a, b + 1], z1], -1)
    p11 = np.stack([x1, h[a + 1, b + 1], z1], -1)
    corners = np.stack([np.stack([p00, p10, p01], 1), np.stack([p01, p10, p11], 1)], 1).reshape(-1, 3, 3)
    ids = (2 * number[:, None] + np.array([0, 1])).ravel()
    return _nearest_triangle(o, d, m, corners, ids)


# -- overlaps and bounds -----------------------------------------------------------------------------
def _result(a):
    return bool(a) if np.ndim(a) == 0 else a


def sphere_sphere(c1, r1, c2, r2):
    """Whether the spheres (centres (..., 3), radii >= 0) overlap or touch; broadcasts (a bool array)."""
    c1, c2 = _points("sphere_sphere", "c1", c1), _points("sphere_sphere", "c2", c2)
    r = _radius("sphere_sphere", "r1", r1) + _radius("sphere_sphere", "r2", r2)
    gap = c1 - c2
    return _result(np.einsum("...i,...i->...", gap, gap) <= r * r)


def closest_point_box(p, box_min, box_max) -> np.ndarray:
    """The point(s) of the box(es) nearest ``p`` (..., 3): ``p`` itself inside; broadcasts."""
    p = _points("closest_point_box", "p", p)
    lo, hi = _box("closest_point_box", box_min, box_max)
    return np.minimum(np.maximum(p, lo), hi)


def sphere_box(c, r, box_min, box_max):
    """Whether the sphere(s) (centre (..., 3), radius >= 0) and the box(es) overlap or touch; broadcasts."""
    c = _points("sphere_box", "c", c)
    r = _radius("sphere_box", "r", r)
    lo, hi = _box("sphere_box", box_min, box_max)
    gap = c - np.minimum(np.maximum(c, lo), hi)
    return _result(np.einsum("...i,...i->...", gap, gap) <= r * r)


def box_box(min1, max1, min2, max2):
    """Whether the axis-aligned boxes overlap or touch (each (..., 3) corners); broadcasts."""
    lo1, hi1 = _box("box_box", min1, max1, "min1", "max1")
    lo2, hi2 = _box("box_box", min2, max2, "min2", "max2")
    return _result(((lo1 <= hi2) & (lo2 <= hi1)).all(-1))


def bounds(vertices, transform=None) -> tuple[np.ndarray, np.ndarray]:
    """(box_min, box_max) of the points ``vertices`` (n, 3), n >= 1, after the 4×4 affine model matrix
    ``transform`` (column vectors, as :meth:`atmos.Pose.matrix`: last row 0 0 0 1) when given."""
    v = _floats("bounds", "vertices", vertices, "finite numbers shaped (n, 3), n >= 1")
    if v.ndim != 2 or v.shape[1] != 3 or len(v) == 0:
        _fail("bounds", "vertices", "finite numbers shaped (n, 3), n >= 1", vertices)
    if transform is not None:
        t = _floats("bounds", "transform", transform, "a finite affine 4×4 matrix (last row 0 0 0 1) or None")
        if t.shape != (4, 4) or not (t[3] == (0.0, 0.0, 0.0, 1.0)).all():
            _fail("bounds", "transform", "a finite affine 4×4 matrix (last row 0 0 0 1) or None", transform)
        v = v @ t[:3, :3].T + t[:3, 3]
    return v.min(0), v.max(0)
