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
