"""Which sprite groups a frame draws, and in which order (thesis 6.2, 7.2.1, 7.2.2).

A *segment* is one group of ``gx × gz`` cells of one height slice: ``(gi, j, gk)``. Culling:

* frustum (7.2.1): a column's padded box (all height slices together) outside one of the 6
  frustum planes culls the whole column;
* empty space (7.2.2): ``max_maps`` from :meth:`CloudSimulation.max_maps` (already the max of the
  two interpolated steps): a column whose map [0] is 0 is skipped; otherwise slice ``j`` is skipped
  where its band's map ``[1 + j // band_height]`` is 0.

Order, back to front: columns by distance of their centre from the camera, farthest first; inside
a column, slices by ``|slice height − camera height|``, farthest first — bottom-up for a camera
above the layer, top-down below it, and from both ends toward the camera's height inside it.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from atmos.plugins.cloud_render.frustum import boxes_outside, frustum_planes
from atmos.plugins.clouds.layout import CloudLayout


@dataclass
class SegmentStats:
    """Counters of one frame: columns and segments drawn or culled, per reason."""
    columns: int = 0
    columns_frustum_culled: int = 0
    columns_empty: int = 0
    segments: int = 0
    segments_frustum_culled: int = 0
    segments_empty: int = 0
    segments_drawn: int = 0
    sprites: int = 0          # vertices submitted: segments_drawn × group cells

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


def select_segments(layout: CloudLayout, camera_pos, view_proj=None, max_maps=None,
                    band_height: int = 1) -> tuple[np.ndarray, SegmentStats]:
    """(segments int32 (n, 3) as (gi, j, gk) in draw order, stats). ``view_proj=None``: no frustum
    culling; ``max_maps=None``: no empty-space skipping."""
    gx, gz = layout.grid
    ny = layout.shape[1]
    cam = np.asarray(camera_pos, np.float64)
    stats = SegmentStats(columns=gx * gz, segments=gx * gz * ny)
    keep = np.ones((gx, gz), bool)
    lo, hi = layout.column_boxes()
    if view_proj is not None:
        outside = boxes_outside(frustum_planes(view_proj), lo, hi)
        keep &= ~outside
        stats.columns_frustum_culled = int(outside.sum())
        stats.segments_frustum_culled = stats.columns_frustum_culled * ny
    slice_ok = np.ones((gx, gz, ny), bool)
    if max_maps is not None:
        maps = np.asarray(max_maps)
        expected = (1 + -(-ny // band_height), gx, gz)
        if maps.shape != expected:
            raise ValueError(f"max_maps must have shape (1 + bands, gx, gz) = {expected}, got {maps.shape}")
        empty = keep & ~(maps[0] > 0)
        stats.columns_empty = int(empty.sum())
        keep &= ~empty
        slice_ok = maps[1 + np.arange(ny) // band_height].transpose(1, 2, 0) > 0
        stats.segments_empty = stats.columns_empty * ny + int((keep[..., None] & ~slice_ok).sum())
    cols = np.argwhere(keep)                                       # (C, 2) as (gi, gk)
    centers = (lo[cols[:, 0], cols[:, 1]] + hi[cols[:, 0], cols[:, 1]]) / 2
    cols = cols[np.argsort(-np.linalg.norm(centers - cam, axis=1), kind="stable")]
    slices = np.argsort(-np.abs(layout.slice_heights() - cam[1]), kind="stable")
    ci, si = np.nonzero(slice_ok[cols[:, 0], cols[:, 1]][:, slices])
    segments = np.stack([cols[ci, 0], slices[si], cols[ci, 1]], -1).astype(np.int32)
    stats.segments_drawn = len(segments)
    stats.sprites = len(segments) * layout.group[0] * layout.group[1]
    return segments, stats
