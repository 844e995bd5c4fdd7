"""Mesh: triangles from numpy arrays (positions, optional normals, indices), simple shapes, and files
(OBJ, glTF/GLB, STL, PLY... through trimesh).

A model's front is its −z, up +y (as :meth:`atmos.Pose.matrix` places it).
"""
from __future__ import annotations

import itertools

import numpy as np

_ids = itertools.count()


class Mesh:
    """``positions`` (n, 3) and ``indices`` (m, 3) (vertex numbers of each triangle, counter-clockwise
    seen from outside), ``normals`` (n, 3) or None: flat-shaded normals are made (each triangle gets
    its own three vertices). Checked here: a ValueError names what is wrong. Immutable once made."""

    def __init__(self, positions, indices, normals=None):
        p = np.asarray(positions, np.float64)
        i = np.asarray(indices)
        if p.ndim != 2 or p.shape[1] != 3 or len(p) == 0 or not np.isfinite(p).all():
            raise ValueError(f"Mesh positions must be a non-empty (n, 3) array of finite numbers, got shape {p.shape}")
        if i.ndim != 2 or i.shape[1] != 3 or len(i) == 0 or not np.issubdtype(i.dtype, np.integer):
            raise ValueError(f"Mesh indices must be a non-empty (m, 3) integer array, got {i.dtype} shape {i.shape}")
        if i.min() < 0 or i.max() >= len(p):
            raise ValueError(f"Mesh indices must lie in 0..{len(p) - 1} (the positions), got {i.min()}..{i.max()}")
        if normals is None:
            p, i, n = _flat(p, i)
        else:
            n = np.asarray(normals, np.float64)
            if n.shape != p.shape or not np.isfinite(n).all():
                raise ValueError(f"Mesh normals must be finite and shaped like positions {p.shape}, got {n.shape}")
        self.positions, self.normals, self.indices = p, n, i.astype(np.uint32)
        for a in (self.positions, self.normals, self.indices):
            a.setflags(write=False)
        self.id = next(_ids)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(box_min, box_max) of the vertices, in model space."""
        return self.positions.min(0), self.positions.max(0)

    @property
    def vertex_data(self) -> bytes:
        """Interleaved float32 position, normal per vertex (what the mesh pass uploads)."""
        return np.hstack([self.positions, self.normals]).astype(np.float32).tobytes()

    @classmethod
    def load(cls, path, smooth: bool = False) -> "Mesh":
        """A mesh from a file trimesh reads (OBJ, glTF/GLB, STL, PLY, ...; a scene is merged into one);
        ``smooth``: its vertex normals, else flat shading."""
        try:
            import trimesh
        except ImportError:
            raise ImportError("Mesh.load needs trimesh (pip install 'atmos[meshes]' or pip install trimesh)") from None
        loaded = trimesh.load(path, force="mesh", process=True)
        if not len(getattr(loaded, "faces", ())):
            raise ValueError(f"{path}: no triangles in this file")
        return cls(loaded.vertices, loaded.faces, loaded.vertex_normals if smooth else None)


def _flat(p: np.ndarray, i: np.ndarray):
    corners = p[i]                                             # (m, 3, 3)
    n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.where(length > 0, n / np.maximum(length, 1e-300), [0.0, 1.0, 0.0])
    return corners.reshape(-1, 3), np.arange(3 * len(i)).reshape(-1, 3), np.repeat(n, 3, axis=0)


def box(size=(1.0, 1.0, 1.0)) -> Mesh:
    """An axis-aligned box of ``size`` (x, y, z) centred on the origin, flat-shaded."""
    s = np.asarray(size, np.float64) / 2
    if s.shape != (3,) or not (np.isfinite(s).all() and (s > 0).all()):
        raise ValueError(f"box size must be three positive numbers, got {size!r}")
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float64) * s
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return Mesh(corners, np.array(faces))


def glider(span: float = 6.0) -> Mesh:
    """A small paper-plane glider, ``span`` metres wide, nose toward −z: two wings and a keel."""
    h = span / 2
    positions = np.array([[0.0, 0.0, -h], [-h, 0.15 * h, 0.6 * h], [h, 0.15 * h, 0.6 * h], [0.0, 0.0, 0.6 * h],
                          [0.0, -0.3 * h, 0.5 * h]])
    return Mesh(positions, np.array([[0, 1, 3], [0, 3, 2], [0, 3, 4]]))


def _positive(name: str, value) -> float:
    v = float(value) if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) else np.nan
    if not (np.isfinite(v) and v > 0):
        raise ValueError(f"{name} must be a finite number > 0 (metres), got {value!r}")
    return v


def _count(name: str, value, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= 1024:
        raise ValueError(f"{name} must be a whole number {lo}..1024, got {value!r}")
    return int(value)


def revolve(profile, segments: int = 32) -> Mesh:
    """The surface swept by turning ``profile`` about the y axis: rows (ρ, y, nρ, ny) in order, ρ >= 0 the
    distance from the axis and (nρ, ny) the outward normal there; a corner is two rows at one point with
    different normals (crisp). ``segments`` around. Triangles face outward; degenerate ones are left out."""
    prof = np.asarray(profile, np.float64)
    if prof.ndim != 2 or prof.shape[1] != 4 or len(prof) < 2 or not np.isfinite(prof).all() or (prof[:, 0] < 0).any():
        raise ValueError(f"revolve profile must be (k >= 2, 4) finite rows (rho >= 0, y, n_rho, n_y), got {prof.shape}")
    segments = _count("segments", segments, 3)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)[:, None]
    c, s = np.cos(phi), np.sin(phi)
    rho, y, nr, ny = (prof[None, :, k] for k in range(4))
    positions = np.stack(np.broadcast_arrays(rho * c, y, rho * s), -1).reshape(-1, 3)
    normals = np.stack(np.broadcast_arrays(nr * c, ny, nr * s), -1).reshape(-1, 3)
    normals /= np.maximum(np.linalg.norm(normals, axis=-1, keepdims=True), 1e-300)
    k = len(prof)
    idx = np.arange((segments + 1) * k).reshape(segments + 1, k)
    a, b, cc, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, cc], -1).reshape(-1, 3), np.stack([a, cc, d], -1).reshape(-1, 3)])
    corner = positions[tris]
    face = np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0])
    area = np.linalg.norm(face, axis=-1)
    tris = tris[area > 1e-12 * max(1.0, float(np.abs(positions).max()) ** 2)]
    face = face[area > 1e-12 * max(1.0, float(np.abs(positions).max()) ** 2)]
    inward = np.einsum("ij,ij->i", face, normals[tris].sum(1)) < 0
    tris[inward] = tris[inward][:, ::-1]                       # counter-clockwise seen from outside
    return Mesh(positions, tris, normals)


def _arc(rho0, y0, radius, a0, a1, n):
    """Profile rows of a circular arc (centre (rho0, y0)) from angle a0 to a1 (radians, 0 = outward)."""
    a = np.linspace(a0, a1, n + 1)
    return np.stack([rho0 + radius * np.cos(a), y0 + radius * np.sin(a), np.cos(a), np.sin(a)], -1)


def sphere(radius: float = 0.5, segments: int = 32, rings: int = 16) -> Mesh:
    """A sphere of ``radius`` centred on the origin, smooth-shaded."""
    r = _positive("sphere radius", radius)
    return revolve(_arc(0.0, 0.0, r, -np.pi / 2, np.pi / 2, _count("rings", rings, 2)), segments)


def cylinder(radius: float = 0.5, height: float = 1.0, segments: int = 32) -> Mesh:
    """A capped cylinder along y, centred on the origin: smooth side, flat caps."""
    r, h = _positive("cylinder radius", radius), _positive("cylinder height", height) / 2
    return revolve([(0, -h, 0, -1), (r, -h, 0, -1), (r, -h, 1, 0), (r, h, 1, 0), (r, h, 0, 1), (0, h, 0, 1)], segments)


def cone(radius: float = 0.5, height: float = 1.0, segments: int = 32) -> Mesh:
    """A cone along y, base ``radius`` at y = -height/2, apex at +height/2: smooth side, flat base."""
    r, h = _positive("cone radius", radius), _positive("cone height", height)
    n = np.array([h, r]) / np.hypot(h, r)                       # the side's outward normal (rho, y)
    return revolve([(0, -h / 2, 0, -1), (r, -h / 2, 0, -1), (r, -h / 2, *n), (0, h / 2, *n)], segments)


def capsule(radius: float = 0.5, height: float = 2.0, segments: int = 32, rings: int = 8) -> Mesh:
    """A capsule along y, ``height`` from tip to tip (at least 2 × radius), centred on the origin."""
    r, total = _positive("capsule radius", radius), _positive("capsule height", height)
    if total < 2 * r:
        raise ValueError(f"capsule height must be at least 2 × radius = {2 * r}, got {height!r}")
    half = total / 2 - r                                         # the straight part's half length
    rings = _count("rings", rings, 1)
    bottom = _arc(0.0, -half, r, -np.pi / 2, 0.0, rings)
    top = _arc(0.0, half, r, 0.0, np.pi / 2, rings)
    return revolve(np.concatenate([bottom, top]), segments)


def torus(radius: float = 1.0, tube: float = 0.25, segments: int = 48, sides: int = 16) -> Mesh:
    """A torus about the y axis: ``radius`` from the centre to the tube's centre, ``tube`` its radius."""
    big, small = _positive("torus radius", radius), _positive("torus tube", tube)
    if small >= big:
        raise ValueError(f"torus tube must be smaller than its radius {big}, got {tube!r}")
    return revolve(_arc(big, 0.0, small, -np.pi, np.pi, _count("sides", sides, 3)), segments)


def plane(size=(1.0, 1.0)) -> Mesh:
    """A flat rectangle (x, z) ``size`` at y = 0, centred on the origin, facing +y."""
    s = np.asarray(size, np.float64) / 2
    if s.shape != (2,) or not (np.isfinite(s).all() and (s > 0).all()):
        raise ValueError(f"plane size must be two positive numbers (x, z), got {size!r}")
    p = np.array([[-s[0], 0, -s[1]], [s[0], 0, -s[1]], [s[0], 0, s[1]], [-s[0], 0, s[1]]])
    return Mesh(p, np.array([[0, 2, 1], [0, 3, 2]]), np.tile([0.0, 1.0, 0.0], (4, 1)))
