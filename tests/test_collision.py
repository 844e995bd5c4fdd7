"""atmos.collision against independent float64 references on fresh random inputs (the ``rng`` seed is
printed: ``ATMOS_TEST_SEED=<seed>`` replays a failure): triangles by plane intersection and signed
areas, boxes by their six faces, spheres by the textbook quadratic, height functions by dense sampling,
grids and the terrain by every triangle of the drawn mesh; edge cases, the cut-off, bad input; the
terrain's and the meshes' raycasts."""
import dataclasses
import functools
import math
import re

import numpy as np
import pytest

from atmos import Transform
from atmos.collision import (Hit, bounds, box_box, closest_point_box, height_normal, ray_box, ray_grid,
                             ray_heightfield, ray_sphere, ray_triangles, segment, sphere_box, sphere_sphere)
from atmos.plugins.mesh import Mesh, MeshInstance, box, glider, mesh_bounds, raycast_instances
from atmos.plugins.terrain import TerrainPlugin, heightfield
from atmos.transform import Pose
from atmos.world import World


def unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v)


def random_dir(rng, n=None):
    v = rng.normal(size=(3,) if n is None else (n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


# -- references --------------------------------------------------------------------------------------
def ref_triangles(o, d, corners, slack=1e-9):
    """(t, triangle) of the nearest hit by plane intersection and signed sub-triangle areas, (inf, None)."""
    o, d, c = np.asarray(o, float), unit(d), np.asarray(corners, float)
    v0, v1, v2 = c[:, 0], c[:, 1], c[:, 2]
    n = np.cross(v1 - v0, v2 - v0)
    nn = np.einsum("ij,ij->i", n, n)
    denom = n @ d
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.einsum("ij,ij->i", n, v0 - o) / denom
        p = o + t[:, None] * d
        bary = [np.einsum("ij,ij->i", np.cross(b - a, p - a), n) / nn for a, b in ((v1, v2), (v2, v0), (v0, v1))]
    ok = (nn > 1e-24 * np.einsum("ij,ij->i", v1 - v0, v1 - v0) * np.einsum("ij,ij->i", v2 - v0, v2 - v0))
    ok &= np.abs(denom) > 1e-12 * np.sqrt(nn)
    ok &= (bary[0] >= -slack) & (bary[1] >= -slack) & (bary[2] >= -slack) & (t >= 0)
    if not ok.any():
        return math.inf, None
    t = np.where(ok, t, np.inf)
    k = int(np.argmin(t))
    return float(t[k]), k


def barycentric(p, tri):
    """Barycentric coordinates of p in the triangle (3, 3) and p's distance from its plane."""
    v0, v1, v2 = np.asarray(tri, float)
    n = unit(np.cross(v1 - v0, v2 - v0))
    off = float((p - v0) @ n)
    q = p - off * n
    m = np.stack([v1 - v0, v2 - v0], 1)
    (u, v), *_ = np.linalg.lstsq(m, q - v0, rcond=None)
    return np.array([1 - u - v, u, v]), off


def ref_box(o, d, lo, hi):
    """(t, outward normal) of the first face plane crossing whose point lies on that face; (inf, None)."""
    d = unit(d)
    best = (math.inf, None)
    for axis in range(3):
        if d[axis] == 0:
            continue
        for plane, sign in ((lo[axis], -1.0), (hi[axis], 1.0)):
            t = (plane - o[axis]) / d[axis]
            p = o + t * d
            others = [a for a in range(3) if a != axis]
            if t >= 0 and all(lo[a] - 1e-9 <= p[a] <= hi[a] + 1e-9 for a in others) and t < best[0]:
                n = np.zeros(3)
                n[axis] = sign
                best = (t, n)
    return best


def ref_sphere(o, d, c, r):
    """The smaller non-negative root of the textbook quadratic |o + t d − c|² = r² (d unit), or inf."""
    d = unit(d)
    oc = o - c
    b, cc = 2 * d @ oc, oc @ oc - r * r
    disc = b * b - 4 * cc
    if disc < 0:
        return math.inf
    roots = sorted([(-b - math.sqrt(disc)) / 2, (-b + math.sqrt(disc)) / 2])
    ahead = [t for t in roots if t >= 0]
    return ahead[0] if ahead else math.inf


def grid_corners(heights, size, centre=(0.0, 0.0)):
    """Every triangle (m, 3, 3) of the grid, built like the terrain's heightfield mesh."""
    nx, nz = heights.shape
    sx, sz = np.broadcast_to(np.asarray(size, float), 2)
    x = centre[0] - sx / 2 + np.arange(nx) * sx / (nx - 1)
    z = centre[1] - sz / 2 + np.arange(nz) * sz / (nz - 1)
    gx, gz = np.meshgrid(x, z, indexing="ij")
    p = np.stack([gx, heights, gz], -1).reshape(-1, 3)
    i = np.arange(nx * nz).reshape(nx, nz)[:-1, :-1].ravel()
    tris = np.stack([i, i + nz, i + 1, i + 1, i + nz, i + nz + 1], -1).reshape(-1, 3)
    return p[tris]


def check_hit(hit, d, t, point=None, atol=1e-9):
    assert hit is not None, f"expected a hit at {t}"
    assert hit.distance == pytest.approx(t, rel=1e-9, abs=atol)
    if point is not None:
        np.testing.assert_allclose(hit.point, point, atol=atol * 10, rtol=1e-9)
    assert np.linalg.norm(hit.normal) == pytest.approx(1.0, abs=1e-12)
    assert hit.normal @ unit(d) <= 1e-12, "the normal faces against the ray"


# -- triangles ---------------------------------------------------------------------------------------
def test_ray_triangles_matches_the_plane_and_area_reference(rng):
    for _ in range(60):
        m = int(rng.integers(1, 40))
        corners = rng.uniform(-5, 5, (m, 1, 3)) + rng.normal(0, 2, (m, 3, 3))
        o = rng.uniform(-12, 12, 3)
        if rng.random() < 0.7:                          # aimed at a random interior point
            w = rng.dirichlet([1, 1, 1]) * 0.9 + 0.1 / 3
            d = w @ corners[rng.integers(m)] - o
        else:
            d = rng.normal(size=3)
        t, k = ref_triangles(o, d, corners)
        hit = ray_triangles(o, d, corners)
        if k is None:
            assert hit is None
            continue
        check_hit(hit, d, t, o + t * unit(d))
        if hit.triangle != k:                           # a tie: both at the same distance
            assert ref_triangles(o, d, corners[[hit.triangle]])[0] == pytest.approx(t, rel=1e-9)
        n = unit(np.cross(*(corners[hit.triangle, 1:] - corners[hit.triangle, 0])))
        assert abs(hit.normal @ n) == pytest.approx(1.0, abs=1e-9)
        lam, off = barycentric(hit.point, corners[hit.triangle])
        assert abs(off) < 1e-9 * (1 + np.abs(corners).max()) and lam.min() > -1e-8
        # the same soup as vertices + indices, shuffled vertex order
        flat = corners.reshape(-1, 3)
        order = rng.permutation(len(flat))
        index = np.argsort(order).reshape(-1, 3)
        same = ray_triangles(o, d, flat[order], index)
        assert same.triangle == hit.triangle and same.distance == pytest.approx(hit.distance, rel=1e-12)
        # the cut-off
        assert ray_triangles(o, d, corners, max_distance=hit.distance * (1 - 1e-9)) is None
        assert ray_triangles(o, d, corners, max_distance=hit.distance).distance == hit.distance


def test_triangles_edges_back_faces_parallel_and_degenerate():
    quad = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    tris = np.array([[0, 1, 2], [2, 1, 3]])
    for target in ((0.5, 0.5), (1.0, 0.0), (0.0, 0.0), (0.3, 0.7), (1.0, 1.0)):   # on the diagonal, corners
        hit = ray_triangles((*target, 3.0), (0, 0, -1), quad, tris)
        check_hit(hit, (0, 0, -1), 3.0, (*target, 0.0))
        np.testing.assert_array_equal(hit.normal, [0, 0, 1])
    back = ray_triangles((0.2, 0.2, -2.0), (0, 0, 1), quad, tris)             # from behind: both faces
    check_hit(back, (0, 0, 1), 2.0)
    np.testing.assert_array_equal(back.normal, [0, 0, -1])
    assert ray_triangles((0.2, 0.2, 1.0), (0, 0, 1), quad, tris) is None       # facing away
    assert ray_triangles((-1, 0.2, 0.0), (1, 0, 0), quad, tris) is None        # in the plane: edge-on
    assert ray_triangles((-1, 0.2, 1e-3), (1, 0, 0), quad, tris) is None       # parallel above it
    assert ray_triangles((1.5, 0.5, 1.0), (0, 0, -1), quad, tris) is None      # beside it
    assert ray_triangles((1 + 1e-6, 0.5, 1.0), (0, 0, -1), quad, tris) is None
    assert ray_triangles((0.2, 0.2, 0.0), (0, 0, 1), quad, tris).distance == 0.0   # starting on it
    # degenerate triangles in front are skipped; the real one behind them is hit
    soup = np.array([[[0, 0, 1], [1, 1, 1], [2, 2, 1]],                        # collinear
                     [[0.2, 0.2, 2], [0.2, 0.2, 2], [1, 0, 2]],                 # two corners the same
                     [[0.2, 0.2, 3]] * 3,                                        # a point
                     [[0, 0, 5], [1, 0, 5], [0, 1, 5]]], float)
    hit = ray_triangles((0.2, 0.2, 0), (0, 0, 1), soup)
    assert hit.triangle == 3 and hit.distance == 5.0
    assert ray_triangles((0, 0, 0), (0, 0, 1), np.zeros((0, 3, 3))) is None
    assert ray_triangles((0, 0, 0), (0, 0, 1), quad, np.zeros((0, 3), int)) is None
    # a long ray, far from the origin of coordinates: relative precision
    far = ray_triangles((1e5 + 0.25, 1e5 + 0.25, 1e4), (0, 0, -1), quad + (1e5, 1e5, 0), tris)
    check_hit(far, (0, 0, -1), 1e4, (1e5 + 0.25, 1e5 + 0.25, 0.0), atol=1e-9)


def test_ties_go_to_the_lower_row_and_the_nearest_wins():
    a = [[-1, -1, 2], [1, -1, 2], [0, 1, 2]]
    b = [[-1, -1, 1], [1, -1, 1], [0, 1, 1]]
    assert ray_triangles((0, 0, 0), (0, 0, 1), np.array([a, b, b], float)).triangle == 1
    assert ray_triangles((0, 0, 0), (0, 0, 1), np.array([a, b, b], float), max_distance=0.5) is None


# -- boxes -------------------------------------------------------------------------------------------
def test_ray_box_matches_the_six_faces_reference(rng):
    for _ in range(300):
        lo = rng.uniform(-5, 5, 3)
        hi = lo + rng.uniform(0.01, 4, 3)
        o = rng.uniform(-10, 10, 3)
        d = rng.uniform(lo, hi) - o if rng.random() < 0.6 else rng.normal(size=3)
        if rng.random() < 0.2:
            d[rng.integers(3)] = 0.0                    # parallel to one pair of slabs
        if not d.any():
            continue
        hit = ray_box(o, d, lo, hi)
        if np.all((lo <= o) & (o <= hi)):
            assert hit.distance == 0.0 and np.array_equal(hit.point, o)
            np.testing.assert_allclose(hit.normal, -unit(d))
            continue
        t, n = ref_box(o, d, lo, hi)
        if n is None:
            assert hit is None
            continue
        assert hit.distance == pytest.approx(t, rel=1e-6, abs=1e-9)        # near edges the ref's slack shows
        assert np.abs(hit.point - np.clip(hit.point, lo, hi)).max() < 1e-9 and hit.normal @ unit(d) < 0
        assert np.isclose(hit.point, np.where(hit.normal < 0, lo, hi), atol=1e-12)[hit.normal != 0].all()
        if hit.normal @ n > 0.5:                        # else near an edge: the ref may take the other face
            np.testing.assert_array_equal(hit.normal, n)
        # the same box as 12 triangles
        tris = mesh_tris(box(hi - lo), (lo + hi) / 2)
        assert ray_triangles(o, d, tris).distance == pytest.approx(hit.distance, rel=1e-9, abs=1e-12)
        assert ray_box(o, d, lo, hi, max_distance=0.999999 * t) is None
        assert ray_box(o, d, lo, hi, max_distance=hit.distance).distance == hit.distance


def mesh_tris(mesh, offset=(0, 0, 0)):
    return mesh.positions[mesh.indices.astype(int)] + offset


def test_ray_box_edge_cases():
    lo, hi = np.zeros(3), np.ones(3)
    check_hit(ray_box((-1, 0.5, 0.5), (1, 0, 0), lo, hi), (1, 0, 0), 1.0, (0, 0.5, 0.5))
    assert ray_box((-1, 1.5, 0.5), (1, 0, 0), lo, hi) is None               # parallel to y slabs, outside
    graze = ray_box((-1, 1.0, 0.5), (1, 0, 0), lo, hi)                       # along the top face: touches
    check_hit(graze, (1, 0, 0), 1.0, (0, 1, 0.5))
    np.testing.assert_array_equal(graze.normal, [-1, 0, 0])
    edge = ray_box((-1, 1.0, 1.0), (1, 0, 0), lo, hi)                        # along an edge
    assert edge.distance == 1.0
    corner = ray_box((-1, -1, -1), (1, 1, 1), lo, hi)                        # through a corner
    check_hit(corner, (1, 1, 1), math.sqrt(3), (0, 0, 0))
    inside = ray_box((0.5, 0.5, 0.5), (0, 2, 0), lo, hi)                     # inside: distance 0
    assert inside.distance == 0.0 and np.array_equal(inside.normal, [0, -1, 0])
    leaving = ray_box((1.0, 0.5, 0.5), (1, 0, 0), lo, hi)                     # on the surface, leaving
    assert leaving.distance == 0.0
    entering = ray_box((1.0, 0.5, 0.5), (-1, 0, 0), lo, hi)                   # on the surface, entering
    assert entering.distance == 0.0 and np.array_equal(entering.normal, [1, 0, 0])
    assert ray_box((2, 0.5, 0.5), (1, 0, 0), lo, hi) is None                 # behind
    flat = ray_box((0.5, 3, 0.5), (0, -1, 0), (0, 1, 0), (1, 1, 1))          # a zero-height box
    assert flat.distance == 2.0 and np.array_equal(flat.normal, [0, 1, 0])
    assert ray_box((-1, 0.5, 0.5), (1, 0, 0), lo, hi, max_distance=0.5) is None


# -- spheres -----------------------------------------------------------------------------------------
def test_ray_sphere_matches_the_quadratic(rng):
    for _ in range(300):
        c, r = rng.uniform(-5, 5, 3), rng.uniform(0.1, 3)
        o = rng.uniform(-12, 12, 3)
        d = c + rng.normal(0, r, 3) - o if rng.random() < 0.7 else rng.normal(size=3)
        hit = ray_sphere(o, d, c, r)
        if np.linalg.norm(o - c) <= r:
            assert hit.distance == 0.0 and np.array_equal(hit.point, o)
            continue
        t = ref_sphere(o, d, c, r)
        if t == math.inf:
            assert hit is None
            continue
        check_hit(hit, d, t, o + t * unit(d), atol=1e-9)
        np.testing.assert_allclose(hit.normal, (hit.point - c) / r, atol=1e-9)
        assert np.linalg.norm(hit.point - c) == pytest.approx(r, rel=1e-12)
        assert ray_sphere(o, d, c, r, max_distance=t * 0.999999) is None


def test_ray_sphere_edge_cases():
    graze = ray_sphere((-5, 1, 0), (1, 0, 0), (0, 0, 0), 1.0)                 # tangent: touches
    check_hit(graze, (1, 0, 0), 5.0, (0, 1, 0))
    np.testing.assert_allclose(graze.normal, [0, 1, 0])
    assert ray_sphere((-5, 1 + 1e-9, 0), (1, 0, 0), (0, 0, 0), 1.0) is None
    assert ray_sphere((5, 0, 0), (1, 0, 0), (0, 0, 0), 1.0) is None          # behind
    assert ray_sphere((0.2, 0, 0), (1, 0, 0), (0, 0, 0), 1.0).distance == 0.0
    assert ray_sphere((1, 0, 0), (1, 0, 0), (0, 0, 0), 1.0).distance == 0.0  # on it, leaving
    point = ray_sphere((0, 0, -3), (0, 0, 1), (0, 0, 0), 0.0)                 # radius 0: a point
    assert point.distance == 3.0 and np.array_equal(point.normal, [0, 0, -1])
    far = ray_sphere((0, 0, -1e6), (0, 0, 1), (0, 0, 0), 1.0)                 # far away, no cancellation
    assert far.distance == 1e6 - 1.0


# -- segments ----------------------------------------------------------------------------------------
def test_a_segment_is_a_ray_cut_at_its_length(rng):
    lo, hi = -np.ones(3), np.ones(3)
    assert segment(ray_box, (0, 0, -5), (0, 0, -1.5), lo, hi) is None
    hit = segment(ray_box, (0, 0, -5), (0, 0, -1.0), lo, hi)
    assert hit.distance == 4.0
    assert segment(ray_sphere, (0, 0, -5), (0, 0, 5), (0, 0, 0), 1.0).distance == 4.0
    tris = rng.normal(0, 2, (20, 3, 3))
    for _ in range(50):
        a, b = rng.normal(0, 4, 3), rng.normal(0, 4, 3)
        want = ray_triangles(a, b - a, tris, max_distance=np.linalg.norm(b - a))
        got = segment(ray_triangles, a, b, tris)
        assert (got is None) == (want is None)
        if got is not None:
            assert got.triangle == want.triangle and got.distance == pytest.approx(want.distance, rel=1e-12)
    with pytest.raises(ValueError, match="segment: a and b must be distinct"):
        segment(ray_box, (1, 2, 3), (1, 2, 3), lo, hi)
    with pytest.raises(TypeError, match="max_distance"):
        segment(ray_box, (0, 0, 0), (1, 0, 0), lo, hi, max_distance=3.0)


# -- height functions --------------------------------------------------------------------------------
def sines(rng, n=4):
    """A random sum of sines (wavelengths >= 10 m) and its exact gradient."""
    amp = rng.uniform(0.5, 3, n)
    k = rng.normal(size=(n, 2))
    k *= (rng.uniform(0.1, 0.6, n) / np.linalg.norm(k, axis=1))[:, None]
    phase = rng.uniform(0, 2 * np.pi, n)

    def height(x, z):
        x, z = np.asarray(x, float), np.asarray(z, float)
        return sum(a * np.sin(kx * x + kz * z + p) for a, (kx, kz), p in zip(amp, k, phase))

    def gradient(x, z):
        c = [a * np.cos(kx * x + kz * z + p) for a, (kx, kz), p in zip(amp, k, phase)]
        return sum(ci * kx for ci, (kx, _) in zip(c, k)), sum(ci * kz for ci, (_, kz) in zip(c, k))
    return height, gradient


def test_ray_heightfield_finds_the_first_crossing_of_dense_sampling(rng):
    step, tol = 0.5, 1e-7
    for _ in range(40):
        height, gradient = sines(rng)
        o = np.array([rng.uniform(-50, 50), rng.uniform(2, 15), rng.uniform(-50, 50)])
        o[1] += float(height(o[0], o[2]))
        d = unit([rng.normal(), -rng.uniform(0.02, 1.0), rng.normal()])
        length = 120.0
        ts = np.linspace(0, length, 120001)                      # 1 mm apart
        p = o + ts[:, None] * d
        f = p[:, 1] - height(p[:, 0], p[:, 2])
        down = np.flatnonzero((f[:-1] > 0) & (f[1:] <= 0))      # entries into the ground
        up = np.flatnonzero((f[:-1] <= 0) & (f[1:] > 0))
        crossings = ts[down] + (ts[down + 1] - ts[down]) * f[down] / (f[down] - f[down + 1])
        hit = ray_heightfield(o, d, height, length, step=step, tolerance=tol)
        if not len(down):
            assert hit is None
            continue
        assert hit is not None
        j = int(np.argmin(np.abs(crossings - hit.distance)))
        assert abs(crossings[j] - hit.distance) < 1e-5, "the hit is a crossing"
        for earlier in range(j):                                 # ones skipped are documented misses
            runs = ts[up[up > down[earlier]]]
            assert len(runs) and runs[0] - ts[down[earlier]] < step + 2e-3
        x, y, z = hit.point
        assert abs(y - float(height(x, z))) < 1e-5
        gx, gz = gradient(x, z)
        np.testing.assert_allclose(hit.normal, unit([-gx, 1.0, -gz]), atol=1e-5)
        assert hit.normal @ d <= 0 and hit.triangle is None


def test_ray_heightfield_edge_cases():
    flat = lambda x, z: np.zeros(np.broadcast(x, z).shape)   # noqa: E731
    hit = ray_heightfield((0, 10, 0), (0, -1, 0), flat, 100.0, step=3.0, tolerance=1e-9)
    assert hit.distance == pytest.approx(10.0, abs=1e-9)
    np.testing.assert_allclose(hit.normal, [0, 1, 0])
    assert ray_heightfield((0, 10, 0), (0, -1, 0), flat, 9.0) is None                 # cut off
    assert ray_heightfield((0, 10, 0), (0, -1, 0), flat, 10.0).distance == pytest.approx(10.0, abs=1e-6)
    assert ray_heightfield((0, 10, 0), (1, 1, 0), flat, 100.0) is None                 # upward
    assert ray_heightfield((0, 10, 0), (1, 0, 0), flat, 100.0) is None                 # level, above
    under = ray_heightfield((0, -1, 0), (1, 0, 0), flat, 100.0)                        # under the ground
    assert under.distance == 0.0 and np.array_equal(under.normal, [-1, 0, 0])
    assert ray_heightfield((0, 0, 0), (0, 1, 0), flat, 100.0).distance == 0.0         # on it

    def spike(x, z):                                     # a ridge 0.2 m wide at x = 5.4, 5 m tall
        return np.where(np.abs(np.asarray(x) - 5.4) < 0.1, 5.0, 0.0) + 0 * np.asarray(z)
    assert ray_heightfield((0, 1, 0), (1, 0, 0), spike, 20.0, step=1.0) is None         # between samples
    thin = ray_heightfield((0, 1, 0), (1, 0, 0), spike, 20.0, step=0.05, tolerance=1e-9)
    assert thin.distance == pytest.approx(5.3, abs=1e-8)


# -- grids and the terrain ---------------------------------------------------------------------------
def test_ray_grid_matches_every_triangle_of_the_grid(rng):
    for case in range(80):
        nx, nz = (int(v) for v in rng.integers(2, 13, 2))
        size = rng.uniform(5, 40) if case % 2 else rng.uniform(5, 40, 2)
        centre = rng.uniform(-10, 10, 2)
        heights = rng.uniform(-3, 3, (nx, nz))
        corners = grid_corners(heights, size, centre)
        span = np.broadcast_to(size, 2)
        o = np.array([centre[0] + rng.uniform(-0.8, 0.8) * span[0], rng.uniform(-5, 12),
                      centre[1] + rng.uniform(-0.8, 0.8) * span[1]])
        d = rng.normal(size=3)
        kind = case % 5
        if kind == 1:
            d[[0, 2]] = 0.0                              # vertical
        elif kind == 2:
            d[rng.integers(0, 2) * 2] = 0.0              # along x or z lines
        elif kind == 3 and nx > 2:                       # exactly along an inner grid line
            o[0] = corners[2 * (nz - 1) * int(rng.integers(1, nx - 1)), 0, 0]
            d[0] = 0.0
        if not d[[0, 2]].any() and not d[1]:
            continue
        hit = ray_grid(o, d, heights, size, centre=centre)
        footprint = np.all(np.abs(o[[0, 2]] - centre) <= span / 2)
        ground = ref_triangles((o[0], 1e3, o[2]), (0, -1, 0), corners)[0] if footprint else math.inf
        if ground < math.inf and o[1] <= 1e3 - ground + 1e-12:     # under the surface: inside
            assert hit.distance == 0.0 and np.array_equal(hit.point, o)
            continue
        t, k = ref_triangles(o, d, corners)
        if k is None:
            assert hit is None, (o, d)
            continue
        check_hit(hit, d, t, o + t * unit(d), atol=1e-9)
        if hit.triangle != k:
            assert ref_triangles(o, d, corners[[hit.triangle]])[0] == pytest.approx(t, rel=1e-9, abs=1e-12)
        lam, off = barycentric(hit.point, corners[hit.triangle])
        assert abs(off) < 1e-8 and lam.min() > -1e-8
        assert ray_grid(o, d, heights, size, centre=centre, max_distance=t * 0.999999) is None


def test_ray_grid_edge_cases():
    heights = np.zeros((3, 3))
    assert ray_grid((-5, 1, 0), (1, 0, 0), heights, 2.0) is None                    # level, above
    assert ray_grid((-5, -1, 0), (1, 0, 0), heights, 2.0) is None                   # outside, under: no walls
    assert ray_grid((-5, 1, 0), (1, -0.5, 0), heights, 2.0) is None                 # reaches it under the edge
    hit = ray_grid((-1.5, 1, 0), (1, -1, 0), heights, 2.0)                           # enters over the edge
    assert hit.point[0] == pytest.approx(-0.5) and hit.point[1] == pytest.approx(0.0, abs=1e-12)
    vertex = ray_grid((0, 1, 0), (0, -1, 0), heights, 2.0)                           # straight onto a vertex
    assert vertex.distance == 1.0 and np.array_equal(vertex.normal, [0, 1, 0])
    assert ray_grid((0.5, 0, 0.5), (0, 1, 0), heights, 2.0).distance == 0.0        # on it: inside
    assert ray_grid((0.5, 1, 0.5), (1, 0.01, 0), heights, 2.0) is None              # leaving, above
    assert ray_grid((2.0, 1, 0), (0, -1, 0), heights, 2.0) is None                  # beside it
    assert ray_grid((1.0, 1, 1.0), (0, -1, 0), heights, 2.0).distance == 1.0        # its far corner
    # the triangle numbers follow the terrain mesh: cell (a, b) holds 2(a(nz-1)+b) and that + 1
    h = np.zeros((4, 5))
    for a in range(3):
        for b in range(4):
            for k, (u, w) in enumerate(((0.2, 0.2), (0.8, 0.8))):
                x, z = -1.5 + a + u, -2 + b + w
                assert ray_grid((x, 1, z), (0, -1, 0), h, (3.0, 4.0)).triangle == 2 * (a * 4 + b) + k


def hessian_bound(f, size, spacing):
    """The largest Frobenius norm of f's Hessian on the terrain square (central differences)."""
    axis = np.arange(-size / 2, size / 2 + spacing, spacing)
    x, z = np.meshgrid(axis, axis, indexing="ij")
    e = spacing / 4
    fxx = (f(x + e, z) - 2 * f(x, z) + f(x - e, z)) / e**2
    fzz = (f(x, z + e) - 2 * f(x, z) + f(x, z - e)) / e**2
    fxz = (f(x + e, z + e) - f(x + e, z - e) - f(x - e, z + e) + f(x - e, z - e)) / (4 * e * e)
    return float(np.sqrt(fxx**2 + 2 * fxz**2 + fzz**2).max())


def test_terrain_raycast_is_the_drawn_mesh(rng):
    terrain = TerrainPlugin(cells=int(rng.integers(6, 40)), size=float(rng.uniform(60, 300)),
                            relief=float(rng.uniform(5, 40)))
    s = terrain.settings
    vertices, indices = heightfield(s.size, s.cells, s.relief)
    corners = vertices[:, :3].astype(np.float64)[indices.reshape(-1, 3).astype(int)]
    exact = grid_corners(vertices[:, 1].astype(np.float64).reshape(s.cells + 1, -1), s.size)
    cell = s.size / s.cells
    top = float(vertices[:, 1].max())
    bound = 1.2 * hessian_bound(terrain.height_at, s.size, cell / 4) * cell**2 + 1e-4
    hits = 0
    for _ in range(60):
        o = np.array([rng.uniform(-0.7, 0.7) * s.size, top + s.relief * rng.uniform(0.01, 1),
                      rng.uniform(-0.7, 0.7) * s.size])
        d = unit([rng.normal(), -rng.uniform(0.2, 1.5), rng.normal()])
        hit = terrain.raycast(o, d)
        t, k = ref_triangles(o, d, exact)
        if k is None:
            assert hit is None
            continue
        hits += 1
        check_hit(hit, d, t, o + t * unit(d), atol=1e-9)
        if hit.triangle != k:
            assert ref_triangles(o, d, exact[[hit.triangle]])[0] == pytest.approx(t, rel=1e-9, abs=1e-12)
        lam, off = barycentric(hit.point, corners[hit.triangle])          # on that triangle as drawn (float32)
        assert abs(off) < 1e-4 and lam.min() > -1e-5
        n = unit(np.cross(*(corners[hit.triangle, 1:] - corners[hit.triangle, 0])))
        assert abs(hit.normal @ n) == pytest.approx(1.0, abs=1e-6) and hit.normal @ d <= 0
        if np.all(np.abs(o[[0, 2]]) < s.size / 2):     # from above: the upper face (outside, it may come under the edge)
            assert hit.normal[1] > 0
        assert abs(float(terrain.height_at(hit.point[0], hit.point[2])) - hit.point[1]) <= bound
    assert hits > 10
    # a new relief re-makes what raycast tests (cached by mesh_key)
    down = terrain.raycast((1.0, 500.0, 2.0), (0, -1, 0))
    terrain.configure(relief=s.relief * 2)
    again = terrain.raycast((1.0, 500.0, 2.0), (0, -1, 0))
    assert again.point[1] == pytest.approx(2 * down.point[1], rel=1e-5, abs=1e-4)
    assert terrain.raycast((1.0, again.point[1] - 0.5, 2.0), (1, 0, 0)).distance == 0.0   # under the ground
    assert terrain.raycast((s.size, 100.0, 0.0), (0, -1, 0)) is None                         # beyond its edge
    assert segment(terrain.raycast, (1.0, 500.0, 2.0), (1.0, again.point[1] + 1, 2.0)) is None
    assert segment(terrain.raycast, (1.0, 500.0, 2.0), (1.0, -100, 2.0)).distance == pytest.approx(again.distance)


def test_terrain_normal_at_is_the_height_formulas_slope(rng):
    terrain = TerrainPlugin()
    x, z = rng.uniform(-128, 128, 50), rng.uniform(-128, 128, 50)
    e = 1e-2                                                     # a five-point stencil: independent of eps
    f = terrain.height_at
    dx = (-f(x + 2 * e, z) + 8 * f(x + e, z) - 8 * f(x - e, z) + f(x - 2 * e, z)) / (12 * e)
    dz = (-f(x, z + 2 * e) + 8 * f(x, z + e) - 8 * f(x, z - e) + f(x, z - 2 * e)) / (12 * e)
    want = np.stack([-dx, np.ones_like(dx), -dz], -1)
    want /= np.linalg.norm(want, axis=-1, keepdims=True)
    got = terrain.normal_at(x, z)
    assert got.shape == (50, 3)
    np.testing.assert_allclose(got, want, atol=1e-6)
    assert terrain.normal_at(0.0, 0.0).shape == (3,)
    assert terrain.normal_at(x[:, None], z[None, :5]).shape == (50, 5, 3)
    # the mesh's own vertex normals sample the same slope (with differences half a cell wide)
    vertices, _ = heightfield(256.0, 71, 30.0)
    some = vertices[rng.integers(0, len(vertices), 20)].astype(np.float64)
    np.testing.assert_allclose(terrain.normal_at(some[:, 0], some[:, 2]), some[:, 3:], atol=0.02)


def test_height_normal_of_a_plane():
    n = height_normal(lambda x, z: 0.5 * x - 2.0 * z + 3.0, np.array([1.0, 7.0]), 2.0)
    np.testing.assert_allclose(n, np.broadcast_to(unit([-0.5, 1.0, 2.0]), (2, 3)), atol=1e-9)


# -- overlaps and bounds -----------------------------------------------------------------------------
def test_overlaps_broadcast_and_match_loops(rng):
    n = 400
    c1, c2 = rng.uniform(-5, 5, (n, 3)), rng.uniform(-5, 5, (n, 3))
    r1, r2 = rng.uniform(0, 3, n), rng.uniform(0, 3, n)
    lo1 = rng.uniform(-5, 5, (n, 3))
    hi1 = lo1 + rng.uniform(0, 4, (n, 3))
    lo2 = rng.uniform(-5, 5, (n, 3))
    hi2 = lo2 + rng.uniform(0, 4, (n, 3))
    ss, sb, bb = sphere_sphere(c1, r1, c2, r2), sphere_box(c1, r1, lo1, hi1), box_box(lo1, hi1, lo2, hi2)
    cp = closest_point_box(c1, lo1, hi1)
    assert ss.shape == sb.shape == bb.shape == (n,) and cp.shape == (n, 3)
    for i in range(n):
        assert ss[i] == (math.dist(c1[i], c2[i]) <= r1[i] + r2[i])
        outside = [max(lo1[i, a] - c1[i, a], 0.0, c1[i, a] - hi1[i, a]) for a in range(3)]
        assert sb[i] == (math.hypot(*outside) <= r1[i])
        assert bb[i] == all(max(lo1[i, a], lo2[i, a]) <= min(hi1[i, a], hi2[i, a]) for a in range(3))
        assert math.dist(cp[i], c1[i]) == pytest.approx(math.hypot(*outside), abs=1e-12)
        samples = rng.uniform(lo1[i], hi1[i], (64, 3))             # nothing in the box is nearer
        assert (np.linalg.norm(samples - c1[i], axis=1) >= math.dist(cp[i], c1[i]) - 1e-12).all()
        assert np.all((lo1[i] <= cp[i]) & (cp[i] <= hi1[i]))
        assert sphere_sphere(c1[i], r1[i], c2[i], r2[i]) is bool(ss[i])   # one pair: a plain bool
    # one box against many spheres
    many = sphere_box(c1, 1.0, (-1, -1, -1), (1, 1, 1))
    assert many.shape == (n,)


def test_overlaps_touching_counts():
    assert sphere_sphere((0, 0, 0), 1.0, (2, 0, 0), 1.0) is True
    assert sphere_sphere((0, 0, 0), 1.0, (2 + 1e-9, 0, 0), 1.0) is False
    assert sphere_sphere((0, 0, 0), 0.0, (0, 0, 0), 0.0) is True
    assert sphere_box((2, 0.5, 0.5), 1.0, (0, 0, 0), (1, 1, 1)) is True
    assert sphere_box((2, 2, 0.5), 1.0, (0, 0, 0), (1, 1, 1)) is False               # near the edge, not on
    assert sphere_box((0.5, 0.5, 0.5), 0.0, (0, 0, 0), (1, 1, 1)) is True            # a point inside
    assert box_box((0, 0, 0), (1, 1, 1), (1, 0, 0), (2, 1, 1)) is True               # face to face
    assert box_box((0, 0, 0), (1, 1, 1), (1 + 1e-12, 0, 0), (2, 1, 1)) is False
    np.testing.assert_array_equal(closest_point_box((0.5, 5, -3), (0, 0, 0), (1, 1, 1)), [0.5, 1, 0])


def test_bounds_under_a_model_matrix(rng):
    for _ in range(20):
        v = rng.normal(0, 3, (int(rng.integers(1, 30)), 3))
        pose = Pose(tuple(rng.uniform(-9, 9, 3)), *rng.uniform(-3, 3, 3))
        m = pose.matrix(rng.uniform(0.2, 3, 3))
        lo, hi = bounds(v, m)
        world = np.array([(m @ np.append(p, 1.0))[:3] for p in v])
        np.testing.assert_allclose(lo, world.min(0), atol=1e-12)
        np.testing.assert_allclose(hi, world.max(0), atol=1e-12)
        np.testing.assert_array_equal(bounds(v)[0], v.min(0))


# -- meshes ------------------------------------------------------------------------------------------
def test_mesh_bounds_and_raycast_instances(rng):
    crate = box((2.0, 4.0, 6.0))
    lo, hi = mesh_bounds(crate)
    np.testing.assert_array_equal(lo, [-1, -2, -3])
    np.testing.assert_array_equal(hi, [1, 2, 3])
    turned = Transform(position=(10, 0, 0), yaw=math.pi / 2, scale=2.0)
    lo, hi = mesh_bounds(crate, turned)                        # a quarter turn swaps x and z, doubled
    np.testing.assert_allclose(lo, [4, -4, -2], atol=1e-12)
    np.testing.assert_allclose(hi, [16, 4, 2], atol=1e-12)

    world = World()
    near = world.create_entity(Transform(position=(0, 0, -10)), MeshInstance(crate))
    far = world.create_entity(Transform(position=(0, 0, -30), scale=(3.0, 1.0, 0.5)), MeshInstance(crate))
    world.create_entity(Transform(position=(0, 0, 10)))         # no mesh: never hit
    plane = glider(6.0)
    pose = Transform(position=(20, 5, 0), yaw=0.7, pitch=0.2, roll=-0.4)
    flyer = world.create_entity(pose, MeshInstance(plane))

    entity, hit = raycast_instances(world, (0, 0, 0), (0, 0, -1))
    assert entity == near and hit.distance == pytest.approx(7.0) and np.allclose(hit.normal, [0, 0, 1])
    assert 0 <= hit.triangle < len(crate.indices)
    entity, hit = raycast_instances(world, (0, 0, 0), (0, 0, -1), ignore=near)
    assert entity == far and hit.distance == pytest.approx(28.5)            # scaled to 3 m deep
    assert raycast_instances(world, (0, 0, 0), (0, 0, -1), max_distance=6.9) is None
    assert raycast_instances(world, (0, 0, 0), (0, 0, 1)) is None
    assert raycast_instances(world, (2.5, 0, 0), (0, 0, -1))[0] == far      # only the wide one there
    assert segment(functools.partial(raycast_instances, world), (0, 0, 0), (0, 0, -8))[0] == near

    m = pose.pose().matrix(pose.scale)
    tris = (plane.positions @ m[:3, :3].T + m[:3, 3])[plane.indices.astype(int)]
    for _ in range(40):
        target = rng.dirichlet([1, 1, 1]) @ tris[rng.integers(len(tris))]
        o = target + random_dir(rng) * rng.uniform(3, 15)
        found = raycast_instances(world, o, target - o)
        t, k = ref_triangles(o, target - o, tris)
        others = [ray_box(o, target - o, *mesh_bounds(crate, world.component_for_entity(e, Transform)))
                  for e in (near, far)]
        if any(h is not None and h.distance < t for h in others):
            continue                                              # a crate is in the way
        assert found[0] == flyer and found[1].distance == pytest.approx(t, rel=1e-9)
        assert found[1].triangle == k or ref_triangles(o, target - o, tris[[found[1].triangle]])[0] == \
            pytest.approx(t, rel=1e-9)


def test_hits_are_frozen_and_read_only():
    hit = ray_box((0, 0, -5), (0, 0, 1), (-1, -1, -1), (1, 1, 1))
    with pytest.raises(dataclasses.FrozenInstanceError):
        hit.distance = 1.0
    with pytest.raises(ValueError):
        hit.point[0] = 1.0
    assert isinstance(hit, Hit) and hit.point.dtype == np.float64 and hit.triangle is None


# -- bad input ---------------------------------------------------------------------------------------
NAN, INF = float("nan"), float("inf")
QUAD = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)
FLAT = lambda x, z: 0.0 * np.asarray(x)   # noqa: E731


@pytest.mark.parametrize("call, words", [
    (lambda: ray_box((0, NAN, 0), (1, 0, 0), (0, 0, 0), (1, 1, 1)), "ray_box: origin must be 3 finite numbers"),
    (lambda: ray_box((0, 0, 0), (0, 0, 0), (0, 0, 0), (1, 1, 1)), "ray_box: direction must be a non-zero"),
    (lambda: ray_box((0, 0, 0), (INF, 0, 0), (0, 0, 0), (1, 1, 1)), "ray_box: direction must be 3 finite"),
    (lambda: ray_box((0, 0), (1, 0, 0), (0, 0, 0), (1, 1, 1)), "ray_box: origin must be 3 finite numbers"),
    (lambda: ray_box((0, 0, 0), (1, 0, 0), (1, 0, 0), (0, 1, 1)), "ray_box: box_max must be >= box_min"),
    (lambda: ray_box((0, 0, 0), (1, 0, 0), (0, 0, 0), (1, 1, 1), max_distance=-1), "max_distance must be a number >= 0"),
    (lambda: ray_box((0, 0, 0), (1, 0, 0), (0, 0, 0), (1, 1, 1), max_distance=NAN), "max_distance must be"),
    (lambda: ray_box((0, 0, 0), (1, 0, 0), [(0, 0, 0)] * 2, [(1, 1, 1)] * 2), "3 finite numbers each"),
    (lambda: ray_sphere((0, 0, 0), (1, 0, 0), (0, 0, 0), -1.0), "ray_sphere: radius must be a finite number >= 0"),
    (lambda: ray_sphere((0, 0, 0), (1, 0, 0), (0, 0, 0), "1"), "ray_sphere: radius must be"),
    (lambda: ray_sphere((0, 0, 0), (1, 0, 0), (0, INF, 0), 1.0), "ray_sphere: centre must be 3 finite"),
    (lambda: ray_triangles((0, 0, 0), (1, 0, 0), np.zeros((4, 3))), "ray_triangles: vertices must be shaped (m, 3, 3)"),
    (lambda: ray_triangles((0, 0, 0), (1, 0, 0), QUAD[0], [[0, 1, 3]]), "triangles must be vertex numbers in 0..2"),
    (lambda: ray_triangles((0, 0, 0), (1, 0, 0), QUAD[0], [[0.0, 1.0, 2.0]]), "triangles must be integer"),
    (lambda: ray_triangles((0, 0, 0), (1, 0, 0), QUAD * NAN), "ray_triangles: vertices must be finite"),
    (lambda: ray_heightfield((0, 1, 0), (1, -1, 0), FLAT, INF), "ray_heightfield: max_distance must be a finite"),
    (lambda: ray_heightfield((0, 1, 0), (1, -1, 0), FLAT, 10.0, step=0), "ray_heightfield: step must be"),
    (lambda: ray_heightfield((0, 1, 0), (1, -1, 0), FLAT, 10.0, tolerance=-1), "tolerance must be"),
    (lambda: ray_heightfield((0, 1, 0), (1, -1, 0), 3.0, 10.0), "ray_heightfield: height must be a numpy"),
    (lambda: ray_heightfield((0, 1, 0), (1, -1, 0), lambda x, z: x * NAN, 10.0), "height(x, z) must return finite"),
    (lambda: ray_heightfield((0, 1, 0), (1, -1, 0), FLAT, 1e9, step=1e-3), "max_distance / step must be at most"),
    (lambda: ray_grid((0, 1, 0), (0, -1, 0), np.zeros(5), 1.0), "ray_grid: heights must be finite numbers shaped (nx, nz)"),
    (lambda: ray_grid((0, 1, 0), (0, -1, 0), np.zeros((1, 5)), 1.0), "ray_grid: heights must be"),
    (lambda: ray_grid((0, 1, 0), (0, -1, 0), np.zeros((2, 2)), -1.0), "ray_grid: size must be a finite number > 0"),
    (lambda: ray_grid((0, 1, 0), (0, -1, 0), np.zeros((2, 2)), 1.0, centre=(0, 0, 0)), "ray_grid: centre must be 2"),
    (lambda: sphere_sphere((0, 0, 0), -1.0, (1, 0, 0), 1.0), "sphere_sphere: r1 must be finite numbers >= 0"),
    (lambda: sphere_sphere((0, 0), 1.0, (1, 0, 0), 1.0), "sphere_sphere: c1 must be finite numbers shaped"),
    (lambda: sphere_box((0, 0, 0), NAN, (0, 0, 0), (1, 1, 1)), "sphere_box: r must be finite numbers >= 0"),
    (lambda: sphere_box((0, 0, 0), 1.0, (0, 2, 0), (1, 1, 1)), "sphere_box: box_max must be >= box_min"),
    (lambda: box_box((0, 0, 0), (1, 1, 1), (0, 0, 0), (-1, 1, 1)), "box_box: max2 must be >= min2"),
    (lambda: closest_point_box("here", (0, 0, 0), (1, 1, 1)), "closest_point_box: p must be finite numbers"),
    (lambda: bounds(np.zeros((0, 3))), "bounds: vertices must be finite numbers shaped (n, 3), n >= 1"),
    (lambda: bounds(np.zeros((2, 3)), np.eye(3)), "bounds: transform must be a finite affine 4×4"),
    (lambda: bounds(np.zeros((2, 3)), np.ones((4, 4))), "bounds: transform must be a finite affine 4×4"),
    (lambda: height_normal(FLAT, 0.0, 0.0, eps=0), "height_normal: eps must be a finite number > 0"),
    (lambda: raycast_instances(World(), (0, 0, 0), (0, 0, 0)), "raycast_instances: direction must be a non-zero"),
    (lambda: mesh_bounds("crate"), "mesh_bounds: mesh must be an atmos Mesh"),
    (lambda: TerrainPlugin().raycast((0, 1, 0), (0, NAN, 0)), "TerrainPlugin.raycast: direction must be 3 finite"),
    (lambda: TerrainPlugin().raycast((0, 1, 0), (0, -1, 0), max_distance=-2.0), "TerrainPlugin.raycast: max_distance"),
])
def test_bad_input_is_named(call, words):
    with pytest.raises(ValueError, match=re.escape(words)):
        call()


def test_a_mesh_instance_still_refuses_what_is_not_a_mesh():
    with pytest.raises(ValueError, match="MeshInstance.mesh must be an atmos Mesh"):
        MeshInstance("crate")
    assert isinstance(Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]), Mesh)
