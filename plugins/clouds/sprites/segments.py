"""Which sprite groups a frame draws, at which level of detail, and in which order (thesis 6.2,
7.2.1, 7.2.2).

A *segment* is one group of ``gx × gz`` cells of one height slice: ``(gi, j, gk, 0)``. At level of
detail ``L`` it is ``(gi, j, gk, L)``: the group's cells in blocks of ``s = 2^L`` per side, slices
``[j·s, (j+1)·s)``, one sprite per block (``gx/s × gz/s`` sprites). A column's level is the
largest ``L`` ≤ ``max_level`` whose block still spans at most ``lod_pixels`` pixels at the
column's centre distance (a cell of ``max(cx, cz)`` spans ``max(cx, cz) · pixel_scale / distance``),
so far columns draw up to 8^L fewer sprites; off (level 0 everywhere) with ``lod_pixels=None``.
Culling:

* frustum (7.2.1): a column's box (all height slices together), padded by the layout's sprite
  radius × 2^level (its blocks' sprites), outside one of the 6 frustum planes culls the column;
* empty space (7.2.2): ``max_maps`` from :meth:`CloudSimulation.max_maps` (already the max of the
  two interpolated steps): a column whose map [0] is 0 is skipped; otherwise slice ``j`` is skipped
  where its band's map ``[1 + j // band_height]`` is 0.

Order, back to front: columns by distance of their centre from the camera, farthest first (so
levels never rise along the order); inside a column, slices (blocks) by ``|centre height − camera
height|``, farthest first — bottom-up for a camera above the layer, top-down below it, and from
both ends toward the camera's height inside it. A level-``L`` block is skipped as empty only if
all its slices are.

Seams: a column boundary plane that (nearly) holds the camera is seen edge-on, and the sprites of
the two columns beside it overlap across it at every depth — drawn one column after the other they
leave a line on screen. So within one sprite diameter of such a boundary the two columns on either
side are drawn as one unit, 2 groups wide (2×2 at a corner), whose blocks the vertex shader walks
toward the camera like any group's. The segment's 4th component packs the level and the unit's
span: :func:`pack`, :func:`unpack`.
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace
from functools import lru_cache

import numpy as np

from atmos.plugins.clouds.sprites.frustum import boxes_outside, frustum_planes
from atmos.plugins.clouds.volume.layout import CloudLayout


MAX_LEVEL = 2          # blocks of up to 4³ cells


@dataclass
class SegmentStats:
    """Counters of one frame: columns and segments drawn or culled, per reason."""
    columns: int = 0
    columns_frustum_culled: int = 0
    columns_empty: int = 0
    segments: int = 0
    segments_frustum_culled: int = 0
    segments_empty: int = 0
    segments_drawn: int = 0   # group-slices (group-blocks at a level) drawn; a merged unit counts each column
    sprites: int = 0          # vertices submitted: Σ segments_drawn × sprites per group at its level
    columns_by_level: tuple = (0,)   # columns drawn (not culled) at level 0, 1, ...

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


def pack(level, span_x=1, span_z=1):
    """A segment's 4th component: level (0..3) | (span x − 1) << 2 | (span z − 1) << 3."""
    return np.asarray(level) | (np.asarray(span_x) - 1) << 2 | (np.asarray(span_z) - 1) << 3


def unpack(code):
    """(level, span x, span z) of a segment's 4th component(s)."""
    code = np.asarray(code)
    return code & 3, 1 + (code >> 2 & 1), 1 + (code >> 3 & 1)


def segment_columns(segments) -> np.ndarray:
    """One row (gi, j, gk, level) per column each segment covers, (m, 4) int."""
    level, sx, sz = unpack(segments[:, 3])
    rows = [np.stack([segments[:, 0] + dx, segments[:, 1], segments[:, 2] + dz, level], -1)[(dx < sx) & (dz < sz)]
            for dx in (0, 1) for dz in (0, 1)]
    return np.concatenate(rows)


def draw_units(layout: CloudLayout, camera, keep, margin: float) -> np.ndarray:
    """(U, 4) int (gi, gk, span x, span z): kept columns, merged in pairs (2×2 at a corner) across a
    column boundary the camera is within ``margin`` of; merged columns must all be kept."""
    gx, gz = layout.grid
    near = []
    for axis, count, size in ((0, gx, layout.group[0] * layout.cell[0]), (2, gz, layout.group[1] * layout.cell[2])):
        t = (float(camera[axis]) - float(layout.lo[axis])) / size
        b = min(max(round(t), 0), count)                  # round half to even, as np.round
        near.append(b if 0 < b < count and abs(t - b) * size < margin else None)
    bx, bz = near
    if bx is None and bz is None:                          # no seam near the camera: every kept column alone
        cells = np.argwhere(keep)
        return np.column_stack([cells, np.ones_like(cells)]).astype(np.int64).reshape(-1, 4)
    taken = (~np.asarray(keep, bool)).tolist()            # a few dozen columns: plain lists beat numpy
    units = []

    def claim(i, k, sx, sz):
        a1, c1 = min(i + sx, gx), min(k + sz, gz)
        for a in range(i, a1):
            for c in range(k, c1):
                if taken[a][c]:
                    return
        for a in range(i, a1):
            for c in range(k, c1):
                taken[a][c] = True
        units.append((i, k, sx, sz))
    if bx is not None and bz is not None:
        claim(bx - 1, bz - 1, 2, 2)
    for k in range(gz) if bx is not None else ():
        claim(bx - 1, k, 2, 1)
    for i in range(gx) if bz is not None else ():
        claim(i, bz - 1, 1, 2)
    units += [(i, k, 1, 1) for i in range(gx) for k in range(gz) if not taken[i][k]]
    return np.array(units, np.int64).reshape(-1, 4)


def max_level(group, shape_y: int, limit: int = MAX_LEVEL) -> int:
    """The deepest level of detail a group size allows: 2^L must divide gx, gz and the layer's height."""
    level = 0
    while level < limit and all(n % (2 << level) == 0 for n in (*group, shape_y)):
        level += 1
    return level


def column_levels(distance, cell_px: float, lod_pixels: float | None, top: int) -> np.ndarray:
    """Level per column: the largest L ≤ ``top`` with ``2^L · cell_px / distance ≤ lod_pixels``."""
    distance = np.asarray(distance, np.float64)
    if lod_pixels is None or top == 0:
        return np.zeros(distance.shape, np.int32)
    span = cell_px / np.maximum(distance, 1e-30)               # pixels one cell spans there
    with np.errstate(divide="ignore"):
        level = np.floor(np.log2(lod_pixels / span))
    return np.clip(level, 0, top).astype(np.int32)


@lru_cache(maxsize=16)
def _geometry(layout: CloudLayout):
    """What a layout's columns look like, computed once per layout: unpadded column boxes (lo, hi),
    their centres, and ``lo``/``hi`` before padding for the per-level frustum boxes."""
    lo, hi = layout.column_boxes(0.0)
    for a in (lo, hi):
        a.flags.writeable = False
    centre = (lo + hi) / 2
    centre.flags.writeable = False
    return lo, hi, centre


def select_segments(layout: CloudLayout, camera_pos, view_proj=None, max_maps=None, band_height: int = 1,
                    lod_pixels: float | None = None, pixel_scale: float = 0.0,
                    top_level: int = MAX_LEVEL) -> tuple[np.ndarray, SegmentStats]:
    """(segments int32 (n, 4) as (gi, j, gk, :func:`pack` (level, span)) in draw order, stats). ``view_proj=None``: no
    frustum culling; ``max_maps=None``: no empty-space skipping; ``lod_pixels=None``: level 0 only
    (else ``pixel_scale`` is the target's pixels per world unit at distance 1, and levels go up to
    ``min(top_level, max_level(group, ny))``). Runs every frame: the layout's geometry is cached."""
    gx, gz = layout.grid
    ny = layout.shape[1]
    cam = np.asarray(camera_pos, np.float64)
    lo, hi, centre = _geometry(layout)
    top = 0 if lod_pixels is None else min(top_level, max_level(layout.group, ny))
    cell_px = max(layout.cell[0], layout.cell[2]) * pixel_scale
    keep = np.ones((gx, gz), bool)
    if view_proj is not None:
        if top:
            levels = column_levels(np.linalg.norm(centre - cam, axis=-1), cell_px, lod_pixels, top)
            pad = layout.pad * (1 << levels).astype(float)[..., None]
        else:
            pad = layout.pad * 1.0
        keep &= ~boxes_outside(frustum_planes(view_proj), lo - pad, hi + pad)
    maps = None
    if max_maps is not None:
        maps = np.asarray(max_maps)
        expected = (1 + -(-ny // band_height), gx, gz)
        if maps.shape != expected:
            raise ValueError(f"max_maps must have shape (1 + bands, gx, gz) = {expected}, got {maps.shape}")
    # the rest depends on these alone: a camera that only turns reuses the last frame's answer
    key = (layout, cam.tobytes(), keep.tobytes(), None if maps is None else (maps.dtype.str, maps.tobytes()),
           band_height, lod_pixels, float(pixel_scale), top)
    if _LAST.get("key") == key:
        return _LAST["segments"], replace(_LAST["stats"])
    segments, stats = _select(layout, cam, keep, maps, band_height, lod_pixels, cell_px, top, view_proj is not None)
    segments.flags.writeable = False
    _LAST.update(key=key, segments=segments, stats=replace(stats))
    return segments, stats


_LAST: dict = {}     # the last select_segments' inputs and answer


def _select(layout, cam, keep, maps, band_height, lod_pixels, cell_px, top, culled):
    """select_segments after the frustum test (``keep``: columns inside it)."""
    gx, gz = layout.grid
    ny = layout.shape[1]
    lo, hi, centre = _geometry(layout)
    stats = SegmentStats(columns=gx * gz, segments=gx * gz * ny)
    if culled:
        stats.columns_frustum_culled = int((~keep).sum())
        stats.segments_frustum_culled = stats.columns_frustum_culled * ny
    keep = keep.copy()
    slice_ok = None
    if maps is not None:
        empty = keep & ~(maps[0] > 0)
        stats.columns_empty = int(empty.sum())
        keep &= ~empty
        slice_ok = maps[1 + np.arange(ny) // band_height].transpose(1, 2, 0) > 0
        stats.segments_empty = stats.columns_empty * ny + int((keep[..., None] & ~slice_ok).sum())
    units = draw_units(layout, cam, keep, 2.0 * layout.pad * (1 << top))
    single = bool((units[:, 2:] == 1).all())
    if single:
        unit_distance = np.linalg.norm(centre[units[:, 0], units[:, 1]] - cam, axis=-1)
    else:
        lo_u = lo[units[:, 0], units[:, 1]]
        hi_u = hi[units[:, 0] + units[:, 2] - 1, units[:, 1] + units[:, 3] - 1]
        unit_distance = np.linalg.norm((lo_u + hi_u) / 2 - cam, axis=-1)
    order = np.argsort(-unit_distance, kind="stable")
    units, unit_distance = units[order], unit_distance[order]
    levels = column_levels(unit_distance, cell_px, lod_pixels, top)
    area = units[:, 2] * units[:, 3]
    stats.columns_by_level = tuple(int(area[levels == L].sum()) for L in range(top + 1))
    if slice_ok is None:
        unit_ok = np.ones((len(units), ny), bool)
    elif single:
        unit_ok = slice_ok[units[:, 0], units[:, 1]]
    else:
        unit_ok = slice_ok[units[:, 0], units[:, 1]]
        for w in np.flatnonzero(units[:, 2] * units[:, 3] > 1):    # merged units: any of their columns
            i, k, sx, sz = units[w]
            unit_ok[w] = slice_ok[i:i + sx, k:k + sz].any(axis=(0, 1))
    parts = []
    for level in range(top, -1, -1):                               # levels fall along the order
        mine, s = (levels == level) if top else slice(None), 1 << level
        u_level = units[mine]
        if not len(u_level):
            continue
        blocks = -(-ny // s)
        ok = unit_ok[mine]
        if s > 1:
            ok = np.pad(ok, ((0, 0), (0, blocks * s - ny))).reshape(-1, blocks, s).any(-1)
        heights = layout.base + (np.arange(blocks) * s + 0.5 * s) * layout.cell[1]
        slices = np.argsort(-np.abs(heights - cam[1]), kind="stable")
        ci, si = np.nonzero(ok[:, slices])
        u = u_level[ci]
        parts.append(np.stack([u[:, 0], slices[si], u[:, 1], pack(level, u[:, 2], u[:, 3])], -1))
        columns = int((u[:, 2] * u[:, 3]).sum())
        stats.sprites += columns * (layout.group[0] // s) * (layout.group[1] // s)
        stats.segments_drawn += columns
    segments = np.concatenate(parts).astype(np.int32) if parts else np.zeros((0, 4), np.int32)
    return segments, stats
