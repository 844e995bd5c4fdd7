"""numpy float64 reference of the sprite vertex stage (``shaders/cloud_render/sprite.vert``).

Given the densities and transmittances of sets A and B (``[x, y, z]`` arrays, the transmittance at
its own shading resolution), the segments and the uniforms, it returns what every
(instance, vertex) outputs, instance-major like the GPU: the clip position (``CULLED`` for empty
cells and cells past the edge), point size, light colour, centre optical depth and coverage.
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.shading.reference import trilinear

CULLED = np.array([0.0, 0.0, 2.0, 1.0])


def group_cells(group) -> np.ndarray:
    """The static vertex buffer: local (x, z) of a group, x-major, (gx·gz, 2) int32."""
    gx, gz = group
    return np.stack(np.meshgrid(np.arange(gx), np.arange(gz), indexing="ij"), -1).reshape(-1, 2).astype(np.int32)


def sprite_vertices(density_a, density_b, trans_a, trans_b, t: float, segments, uniforms: dict, view_proj,
                    sun_color, ambient) -> dict:
    """Arrays over (instances × vertices): ``position`` (n, 4), ``size``, ``light`` (n, 3), ``tau``,
    ``coverage``, ``visible``. ``trans_a``/``trans_b`` None: no shading (T = 1)."""
    u = uniforms
    shape = np.array(u["volume_shape"])
    gx, gz = u["group_size"]
    local = group_cells((gx, gz))
    seg = np.asarray(segments, np.int64)
    cells = np.stack([seg[:, None, 0] * gx + local[None, :, 0], np.broadcast_to(seg[:, None, 1], (len(seg), len(local))),
                      seg[:, None, 2] * gz + local[None, :, 1]], -1).reshape(-1, 3)
    inside = (cells < shape).all(-1)
    c = np.minimum(cells, shape - 1)
    a = np.asarray(density_a, np.float64)[c[:, 0], c[:, 1], c[:, 2]]
    b = np.asarray(density_b, np.float64)[c[:, 0], c[:, 1], c[:, 2]]
    d = a * (1.0 - t) + b * t
    visible = inside & (d > 0)
    if trans_a is None:
        T = np.ones(len(c))
    else:
        points = (c + 0.5) / shape * np.array(np.shape(trans_a)) - 0.5
        T = trilinear(np.asarray(trans_a, np.float64), points) * (1 - t) + \
            trilinear(np.asarray(trans_b, np.float64), points) * t
    world = np.asarray(u["layer_min"]) + (c + 0.5) * np.asarray(u["cell_size"])
    clip = np.concatenate([world, np.ones((len(c), 1))], 1) @ np.asarray(view_proj, np.float64).T
    diameter = u["base_diameter"] * (0.5 + 0.5 * np.minimum(d, 1.0))
    px = diameter * u["pixel_scale"] / np.maximum(clip[:, 3], 1e-6)
    out = {"position": np.where(visible[:, None], clip, CULLED),
           "size": np.where(visible, np.clip(px, 1.0, u["max_point_size"]), 1.0),
           "light": np.where(visible[:, None], np.outer(T, sun_color) + np.asarray(ambient), 0.0),
           "tau": np.where(visible, u["tau_scale"] * d / np.maximum(diameter, 1e-30) ** 2, 0.0),
           "coverage": np.where(visible, np.clip(px, 0.0, 1.0) ** 2, 0.0),
           "visible": visible}
    return out
