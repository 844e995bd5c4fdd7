"""numpy float64 references of the far field's GPU measures (``clouds/far_field/cover.comp``,
``clouds/far_field/light_by_rank.comp``) and of its pattern."""
from __future__ import annotations

import numpy as np

from atmos.plugins.clouds.volume.edge import edge_weight
from atmos.plugins.clouds.light.medium import octave_transmittances
from atmos.plugins.clouds.shadows.reference import shifted


def volume_cover(sums_a, sums_b, t: float, a_shift, threshold: float, fade: float) -> float:
    """Edge-weighted covered fraction of the columns of mix(A, B, t); ``sums_a/b`` (nx, nz), A read at
    ``c + a_shift`` (zero past its edge)."""
    sums = (1.0 - t) * shifted(np.asarray(sums_a, np.float64), a_shift) + t * np.asarray(sums_b, np.float64)
    n = np.array(sums.shape)
    uv = np.stack(np.meshgrid(*((np.arange(m) + 0.5) / m for m in n), indexing="ij"), -1)
    w = edge_weight(uv, fade)
    return float((w * (sums > threshold)).sum() / max(w.sum(), 1e-30))


def volume_transitions(sums_a, sums_b, t: float, a_shift, threshold: float, fade: float) -> float:
    """cover.comp's ``transitions``: the fraction of neighbouring column pairs (along x and along z) of
    mix(A, B, t) that differ in cover (sum above ``threshold``), each weighted by the lesser edge weight
    of the two: the cover's changes per cell along a line."""
    sums = (1.0 - t) * shifted(np.asarray(sums_a, np.float64), a_shift) + t * np.asarray(sums_b, np.float64)
    n = np.array(sums.shape)
    uv = np.stack(np.meshgrid(*((np.arange(m) + 0.5) / m for m in n), indexing="ij"), -1)
    w, covered = edge_weight(uv, fade), sums > threshold
    wx, wz = np.minimum(w[1:], w[:-1]), np.minimum(w[:, 1:], w[:, :-1])
    differ = (wx * (covered[1:] != covered[:-1])).sum() + (wz * (covered[:, 1:] != covered[:, :-1])).sum()
    return float(differ / max(wx.sum() + wz.sum(), 1e-30))


def column_quantiles(sums_a, sums_b, t: float, a_shift, fade: float, count: int = 33) -> np.ndarray:
    """(count,) edge-weighted quantiles 0 .. 1 of the column sums of mix(A, B, t) (``cover.comp``'s
    column_quantiles, which bins the sums into a histogram: within one bin of these): 0 inside the
    empty columns' share, else the weighted empirical distribution of the others, linear between them."""
    sums = (1.0 - t) * shifted(np.asarray(sums_a, np.float64), a_shift) + t * np.asarray(sums_b, np.float64)
    n = np.array(sums.shape)
    uv = np.stack(np.meshgrid(*((np.arange(m) + 0.5) / m for m in n), indexing="ij"), -1)
    w, s = np.round(edge_weight(uv, fade) * 1024.0).ravel(), sums.ravel()     # cover.comp's fixed point
    full = (s > 1e-6) & (w > 0)
    total, empty = w.sum(), w[(s <= 1e-6)].sum()
    order = np.argsort(s[full])
    values, cum = s[full][order], empty + np.cumsum(w[full][order])
    target = total * np.linspace(0.0, 1.0, count)
    out = np.interp(target, np.concatenate([[empty], cum]), np.concatenate([[0.0], values]))
    return np.where(target <= empty, 0.0, out) if total > 0 else np.zeros(count)


def shifted_volume(volume, a_shift) -> np.ndarray:
    """``volume`` (nx, ny, nz) read at ``[i + a_shift.x, j, k + a_shift.z]``, zero past its edge (set A on
    B's grid, as columns.glsl's column_density reads it)."""
    a = np.asarray(volume, np.float64)
    nx, ny, nz = a.shape
    out = np.zeros_like(a)
    src_x, src_z = np.arange(nx) + int(a_shift[0]), np.arange(nz) + int(a_shift[2])
    okx, okz = (src_x >= 0) & (src_x < nx), (src_z >= 0) & (src_z < nz)
    out[np.ix_(okx, np.arange(ny), okz)] = a[np.ix_(src_x[okx], np.arange(ny), src_z[okz])]
    return out


def column_profile(density_a, density_b, t: float, a_shift, fade: float, quantiles, heights: int | None = None) -> np.ndarray:
    """``cover.comp``'s profile (intervals, heights, 2) of mix(A, B, t) (``density_a/b`` (nx, ny, nz), A
    read at ``c + a_shift``, zero past its edge; densities clamped to [0, 1]): each covered column (sum
    above 1e-6, edge weight ``fade``) adds w × its density at the ``heights`` samples (default ny; the
    nearest cell) to the rank interval k of ``quantiles`` (:func:`column_quantiles`) its sum lies in;
    [k, j] = (density per unit column sum in cells, share of the column above sample j), an interval
    without columns takes the nearest one's (above first); none at all: uniform."""
    shifted_a, b = shifted_volume(density_a, a_shift), np.asarray(density_b, np.float64)
    nx, ny, nz = b.shape
    heights = ny if heights is None else int(heights)
    d = np.clip((1.0 - t) * shifted_a + t * b, 0.0, 1.0)
    sums = (1.0 - t) * shifted_a.sum(1) + t * b.sum(1)
    uv = np.stack(np.meshgrid((np.arange(nx) + 0.5) / nx, (np.arange(nz) + 0.5) / nz, indexing="ij"), -1)
    units = np.round(edge_weight(uv, fade) * 1024.0)                   # cover.comp's fixed point
    q = np.asarray(quantiles, np.float64)
    intervals = len(q) - 1
    rows = np.minimum(((np.arange(heights) + 0.5) * ny / heights).astype(np.int64), ny - 1)
    take = (sums > 1e-6) & (units > 0)
    k = np.minimum(np.searchsorted(q, sums[take], side="right") - 1, intervals - 1).clip(0)
    profile = np.zeros((intervals, heights))
    np.add.at(profile, k, units[take][:, None] * d.transpose(0, 2, 1)[take][:, rows])
    total = profile.sum(1)
    out = np.zeros((intervals, heights, 2))
    full = np.flatnonzero(total > 0)
    for i in range(intervals):
        if not len(full):
            out[i, :, 0], out[i, :, 1] = 1.0 / ny, 1.0 - (np.arange(heights) + 0.5) / heights
            continue
        dist = np.abs(full - i) * 2 + (full < i)                      # nearest, above first on a tie
        src = full[np.argmin(dist)]
        p = profile[src]
        out[i, :, 0] = p * heights / (total[src] * ny)
        out[i, :, 1] = (p[::-1].cumsum()[::-1] - 0.5 * p) / total[src]
    return out


def light_by_rank(sums_a, sums_b, density_a, density_b, t: float, a_shift, fade: float, quantiles, *, heights: int,
                  attenuation: float, column_tau: float, trans_a=None, trans_b=None, field_a=None, field_b=None,
                  bins: int = 16) -> dict:
    """``light_by_rank.comp`` of mix(A, B, t) (A read at ``c + a_shift``: ``sums_a/b`` (nx, nz) column sums
    and ``density_a/b`` (nx, ny, nz) zero past its edge; the optional sun transmittance ``trans_a/b`` and
    diffusion field ``field_a/b`` (x, y, z, 4) on their own grids, each read at the texel nearest a density
    cell's centre, clamped): per rank interval of ``quantiles`` the edge-weighted mean over its covered
    columns of each column's mean octave transmittances (medium.octave_transmittances) and (phi, F) at its ``heights`` samples, weighted
    by density × the vertical transmittance to the column's top (row 0) or base (row 1); per height
    bin (of min(heights, bins)) the columns' density-weighted octave transmittances and (phi, F); and the edge-weighted mean of each
    column's thickness, sqrt(12 var + 1 / heights²) of its density's height (as a layer fraction, at most
    1: a uniform slab's); and the mean height fraction of the samples weighted as the sun's rows are.
    Returns dict sun (32, 2, 4), height (32, 2), thickness (32,), sun_profile (32, bins, 4) and, with
    a field, field (32, 2, 4), field_profile (32, bins, 4); filled as the shader fills them."""
    def mixed(a, b, cells):
        """mix(A, B, t) of grids a, b (x, y, z, ...) at their texels nearest density ``cells`` (n, 3)
        (A's at the cells + a_shift), each index clamped to its grid."""
        out = []
        for grid, shift in ((np.asarray(a, np.float64), np.array([a_shift[0], 0, a_shift[2]])), (np.asarray(b, np.float64), 0)):
            m = np.array(grid.shape[:3])
            i = np.clip(((cells + shift + 0.5) / n * m).astype(np.int64), 0, m - 1)
            out.append(grid[i[:, 0], i[:, 1], i[:, 2]])
        return (1.0 - t) * out[0] + t * out[1]

    n = np.array(np.shape(density_b))
    nx, ny, nz = n
    density = (1.0 - t) * shifted_volume(density_a, a_shift) + t * np.asarray(density_b, np.float64)
    sums = (1.0 - t) * shifted(np.asarray(sums_a, np.float64), a_shift) + t * np.asarray(sums_b, np.float64)
    uv = np.stack(np.meshgrid((np.arange(nx) + 0.5) / nx, (np.arange(nz) + 0.5) / nz, indexing="ij"), -1)
    units = np.round(edge_weight(uv, fade) * 1024.0)
    q = np.asarray(quantiles, np.float64)
    rows = np.minimum(((np.arange(heights) + 0.5) * ny / heights).astype(np.int64), ny - 1)
    bins = min(int(heights), int(bins))
    in_bin = np.arange(heights) * bins // heights
    field = field_a is not None and field_b is not None
    weight, sun_sum, field_sum = np.zeros((32, 2)), np.zeros((32, 2, 4)), np.zeros((32, 2, 4))
    height_sum = np.zeros((32, 2))
    thickness_sum = np.zeros(32)
    y = (rows + 0.5) / ny
    bin_weight, bin_sum, bin_sun = np.zeros((32, bins)), np.zeros((32, bins, 4)), np.zeros((32, bins, 4))
    for x, z in zip(*np.nonzero((sums > 1e-6) & (units > 0))):
        k = min(max(int(np.searchsorted(q, sums[x, z], side="right")) - 1, 0), 31)
        cells = np.stack([np.full(heights, x), rows, np.full(heights, z)], -1)
        d = np.clip(density[x, rows, z], 0.0, 1.0)
        tau = column_tau * units[x, z] / 1024.0 * ny / heights * d
        below = np.cumsum(tau)
        seen = d[:, None] * np.stack([np.exp(-(below[-1] - below + 0.5 * tau)), np.exp(-(below - 0.5 * tau))], -1)
        T = np.ones(heights) if trans_a is None else np.clip(mixed(trans_a, trans_b, cells), 0.0, 1.0)
        sun = octave_transmittances(T, attenuation)
        v = np.zeros((heights, 4))
        if field:
            f = mixed(field_a, field_b, cells)
            phi = np.clip(f[:, 0], 0.0, 8.0)
            v = np.concatenate([phi[:, None], np.clip(f[:, 1:], -phi[:, None], phi[:, None])], -1)
        dw, dv, dsun = np.zeros(bins), np.zeros((bins, 4)), np.zeros((bins, 4))
        np.add.at(dw, in_bin, d)
        np.add.at(dv, in_bin, d[:, None] * v)
        np.add.at(dsun, in_bin, d[:, None] * sun)
        has = dw > 0
        bin_weight[k, has] += units[x, z]
        bin_sum[k, has] += units[x, z] * dv[has] / dw[has, None]
        bin_sun[k, has] += units[x, z] * dsun[has] / dw[has, None]
        s = seen.sum(0)
        mass = max(d.sum(), 1e-30)
        mean = (d * y).sum() / mass
        thickness = min(np.sqrt(max(12.0 * ((d * y * y).sum() / mass - mean ** 2), 0.0) + 1.0 / heights ** 2), 1.0)
        thickness_sum[k] += units[x, z] * thickness if s[0] > 0 else 0.0
        for view in np.flatnonzero(s > 0):
            weight[k, view] += units[x, z]
            sun_sum[k, view] += units[x, z] * (seen[:, view, None] * sun).sum(0) / s[view]
            height_sum[k, view] += units[x, z] * (seen[:, view] * y).sum() / s[view]
            field_sum[k, view] += units[x, z] * (seen[:, view, None] * v).sum(0) / s[view]
    filled = np.flatnonzero(weight[:, 0] > 0)
    out = {"sun": np.ones((32, 2, 4)), "height": np.full((32, 2), 0.5), "thickness": np.ones(32),
           "sun_profile": np.ones((32, bins, 4))}
    if field:
        out.update(field=np.zeros((32, 2, 4)), field_profile=np.zeros((32, bins, 4)))
    for i in range(32):
        if not len(filled):
            continue
        k = filled[np.argmin(np.abs(filled - i) * 2 + (filled < i))]      # nearest, above first on a tie
        w = weight[k][:, None]
        out["sun"][i] = np.where(w > 0, sun_sum[k] / np.maximum(w, 1e-300), 1.0)
        out["height"][i] = np.where(w[:, 0] > 0, np.minimum(height_sum[k] / np.maximum(w[:, 0], 1e-300), 1.0), 0.5)
        out["thickness"][i] = thickness_sum[k] / weight[k, 0] if weight[k, 0] > 0 else 1.0
        b = bin_weight[k][:, None]
        out["sun_profile"][i] = np.where(b > 0, bin_sun[k] / np.maximum(b, 1e-300), out["sun"][i, 0])
        if field:
            out["field"][i] = np.where(w > 0, field_sum[k] / np.maximum(w, 1e-300), 0.0)
            out["field_profile"][i] = np.where(b > 0, bin_sum[k] / np.maximum(b, 1e-300), out["field"][i, 0])
    return out


def field_fbm(xz, octaves, offsets, tile_size: float, channel: int = 0, weight_bits: int | None = None) -> np.ndarray:
    """The fbm (...,) of ``clouds/far_field/field.glsl`` at world ``xz`` (..., 2), mip 0: ``octaves`` the
    four downloaded textures (size, size, 4) [x, y, channel] (``OctaveTextures.download``), octave k read
    at its own turned uv (:func:`atmos.plugins.clouds.far_field.pattern.octave_uv`), ``offsets`` (4, 2)
    each octave's drift in its uv (:func:`.layer.drift`), ``tile_size`` the layer's tile (m,
    FarFieldLayer.tile_size); bilinear with repeat, texel i centred at (i + 0.5)/size; ``channel``: the
    channel read (pattern.CHANNEL_STEPS: the point, the relief's samples toward and away from the sun);
    ``weight_bits``: filtered as a texture unit with that many bits of sub-texel weight would (:func:`.cover.sample`)."""
    from atmos.plugins.clouds.far_field.cover import sample
    from atmos.plugins.clouds.far_field.pattern import octave_uv
    from atmos.tile_octaves import WEIGHTS
    uv = octave_uv(xz, offsets, tile_size)
    return sum(w * sample(np.asarray(tex, np.float64)[..., channel], uv[k], weight_bits)
               for k, (w, tex) in enumerate(zip(WEIGHTS, octaves)))


def field_rank(fbm, quantiles) -> np.ndarray:
    """The exact rank of one table level (field.glsl's far_rank_table row): the fraction of the layer's
    fbm at or below ``fbm`` (linear between the ``quantiles``, 0 below the first, 1 above the last)."""
    q = np.asarray(quantiles, np.float64)
    return np.interp(fbm, q, np.linspace(0.0, 1.0, len(q)))


def level_rank(fbm, level, quantiles) -> np.ndarray:
    """The exact rank of field.glsl's fbm_rank: :func:`field_rank` in table rows m0 = min(floor(m), L − 2)
    and m0 + 1 of ``quantiles`` (L, QUANTILES) mixed by m − m0, m = ``level`` clamped to 0 .. L − 1 (field_level)."""
    q = np.asarray(quantiles, np.float64)
    fbm, level = np.broadcast_arrays(np.asarray(fbm, np.float64), np.asarray(level, np.float64))
    m = np.clip(level, 0.0, len(q) - 1.0)
    m0 = np.minimum(np.floor(m).astype(np.int64), len(q) - 2)
    t = m - m0
    out = np.empty(fbm.shape)
    for k in range(len(q) - 1):
        at = m0 == k
        out[at] = (1.0 - t[at]) * field_rank(fbm[at], q[k]) + t[at] * field_rank(fbm[at], q[k + 1])
    return out


def table_rank(fbm, level, table, span, weight_bits: int | None = None, dtype=np.float32) -> np.ndarray:
    """fbm_rank's lookup: far_rank_table (:func:`.cover.rank_table`'s ``table``, stored as ``dtype``) read
    bilinear, clamped to the edge, at x = (fbm − span[0]) · span[1], y = (m + 0.5) / rows (m: ``level``
    clamped as field_level); ``weight_bits``: float32 coordinates and sub-texel weights rounded to that
    many bits (:func:`.cover.sample`), None: exact."""
    t = np.asarray(np.asarray(table, np.float64).astype(dtype), np.float64)
    rows, cols = t.shape
    fbm, level = np.broadcast_arrays(np.asarray(fbm, np.float64), np.asarray(level, np.float64))
    m = np.clip(level, 0.0, rows - 1.0)
    if weight_bits is None:
        p = np.stack([(fbm - span[0]) * span[1] * cols - 0.5, m], -1)
    else:
        f32 = np.float32
        x = (fbm.astype(f32) - f32(span[0])) * f32(span[1])
        y = (m.astype(f32) + f32(0.5)) / f32(rows)
        p = np.stack([x * f32(cols) - f32(0.5), y * f32(rows) - f32(0.5)], -1).astype(np.float64)
    i0 = np.floor(p).astype(np.int64)
    w = p - i0
    if weight_bits is not None:
        w = np.round(w * 2.0 ** int(weight_bits)) / 2.0 ** int(weight_bits)
    at = lambda di, dj: t[np.clip(i0[..., 1] + dj, 0, rows - 1), np.clip(i0[..., 0] + di, 0, cols - 1)]
    return ((1 - w[..., 1]) * ((1 - w[..., 0]) * at(0, 0) + w[..., 0] * at(1, 0))
            + w[..., 1] * ((1 - w[..., 0]) * at(0, 1) + w[..., 0] * at(1, 1)))


def rank_table_error(quantiles, table, span, weight_bits: int | None = None, dtype=np.float32) -> tuple[float, float]:
    """(resampling, lookup) bounds on |:func:`table_rank` − :func:`level_rank`|: their sum bounds it.
    Resampling: a row's linear interpolation between columns is the rank itself except in a cell that
    holds quantiles; the error is linear between them and the cell's ends, so its most is at one of
    them (evaluated at each). Lookup, with D = the table's largest step between columns and E between
    rows: storage (half an ulp of ``dtype`` below 1), float32 coordinates (a few ulps of the texture
    coordinate: 4 · 2^-24 texels per column and per row, times D and E) and, with ``weight_bits`` b, a
    weight off by up to 2^-(b+1) along each axis (a sample moves by 2^-(b+1) · (D + E) at most)."""
    q, t = np.asarray(quantiles, np.float64), np.asarray(table, np.float64)
    rows, cols = t.shape
    columns = span[0] + (np.arange(cols) + 0.5) / (cols * span[1])
    ranks = np.linspace(0.0, 1.0, q.shape[1])
    resample = max(float(np.abs(np.interp(row, columns, t[m]) - np.interp(row, row, ranks)).max())
                   for m, row in enumerate(q))
    d = float(np.abs(np.diff(t, axis=1)).max())
    e = float(np.abs(np.diff(t, axis=0)).max()) if rows > 1 else 0.0
    lookup = np.finfo(dtype).eps / 4.0 + 4.0 * 2.0 ** -24 * (cols * d + rows * e)
    if weight_bits is not None:
        lookup += 2.0 ** -(int(weight_bits) + 1) * (d + e)
    return resample, float(lookup)


def column_at_rank(rank, columns) -> np.ndarray:
    """field.glsl's far_quantile: the volume's column sum (cells) at ``rank`` (...,), linear between
    its ``columns`` quantiles (:func:`column_quantiles`)."""
    c = np.asarray(columns, np.float64)
    return np.interp(np.clip(rank, 0.0, 1.0), np.linspace(0.0, 1.0, len(c)), c)


MIN_SLANT = 0.1     # field.glsl's cap on a slant's sin (the view's at the horizon, the sun's)


def far_relief(ranks, columns, tau_cell: float, sun_y: float) -> np.ndarray:
    """field.glsl's far_relief (...,): 3/16 of the difference between the column optical depths
    (``tau_cell`` × :func:`column_at_rank` of ``columns``) at the relief's samples toward the sun and away
    from it (``ranks`` (..., 4): the channels, pattern.CHANNEL_STEPS) over max(``sun_y``, MIN_SLANT)."""
    r = np.asarray(ranks, np.float64)
    return 0.1875 * tau_cell * (column_at_rank(r[..., 1], columns) - column_at_rank(r[..., 2], columns)) / max(sun_y, MIN_SLANT)


def relief_light(s, d) -> np.ndarray:
    """field.glsl's relief_light: the octaves' sun transmittances ``s`` moved by the relief's optical
    depths ``d`` toward 0 (d > 0) or 1, at most as far as the nearer bound (odd in d: no light added)."""
    s = np.asarray(s, np.float64)
    return s - np.minimum(s, 1.0 - s) * np.tanh(np.clip(d, -10.0, 10.0))


def slant_rank(rank, height: float, cot, cover: float, crossings, tile_size: float) -> tuple[np.ndarray, np.ndarray]:
    """far.comp's slant_rank: (rank, optical depth factor) of points of ``rank`` (...,) of a layer of
    clouds ``height`` (m) high seen with cot(elevation) ``cot`` (...,): the pattern crosses its cover n
    times per metre (``crossings`` per tile at quantile 1 − cover, :func:`.cover.pattern_crossings`); a
    cloud as a spheroid of radii a = cover / n across and b = height / 2 up widens by 2 (√(a² + b²
    cot²) − a) along the view, and with exponential gaps of mean 2 (1 − cover) / n the layer covers
    c' = 1 − (1 − c) exp(−widening / gap); ranks above 1 − c' spread over 1 − c .. 1, the optical depth
    × c / c'."""
    rank, cot = np.broadcast_arrays(np.asarray(rank, np.float64), np.asarray(cot, np.float64))
    c = float(np.clip(cover, 0.0, 1.0))
    n = float(np.interp(1.0 - c, np.linspace(0.0, 1.0, len(crossings)), crossings)) / float(tile_size)
    if not (0.0 < c < 1.0 and n > 0.0 and height > 0.0):
        return rank, np.ones_like(rank)
    a, b = c / n, 0.5 * float(height)
    widen = 2.0 * (np.sqrt(a * a + b * b * cot * cot) - a)
    c2 = 1.0 - (1.0 - c) * np.exp(-widen * n / (2.0 * (1.0 - c)))
    return 1.0 - c + (rank - (1.0 - c2)) * c / c2, c / c2


def far_field_alpha(xz, dirs, height: float, octaves, offsets, tile_size: float, quantiles, columns,
                    column_tau: float, cover: float, crossings, thickness: float = 1.0,
                    weight_bits: int | None = None) -> np.ndarray:
    """far.comp's opacity (...,) where the view ``dirs`` (..., 3, unit) meet the middle plane at world
    ``xz`` (..., 2), mip 0, before the edge, horizon and scene fades: thickness · column_tau (sigma_t ·
    cell height) · the volume's column sum at the point's rank, both as :func:`slant_rank` gives them
    for clouds ``height`` (m) high at the ray's slant (``cover``, ``crossings``: the layer's), seen along
    the slant 1 / max(|dir_y|, MIN_SLANT); ``weight_bits``: the octaves filtered as by :func:`field_fbm`."""
    dirs = np.asarray(dirs, np.float64)
    slant = np.maximum(np.abs(dirs[..., 1]), MIN_SLANT)
    rank = field_rank(field_fbm(xz, octaves, offsets, tile_size, weight_bits=weight_bits), quantiles)
    rank, factor = slant_rank(rank, height, np.linalg.norm(dirs[..., [0, 2]], axis=-1) / slant, cover, crossings, tile_size)
    tau = float(thickness) * float(column_tau) * factor * column_at_rank(rank, columns)
    return 1.0 - np.exp(-tau / slant)


def far_optical_depth(xz, octaves, offsets, tile_size: float, quantiles, columns, column_tau: float) -> np.ndarray:
    """The far field's vertical optical depth (...,) at world ``xz`` (..., 2), mip 0: ``column_tau`` (optical
    depth per summed cell) × the volume's column sum at the point's rank (far.comp's tau.x; the ground
    shadows' term beyond the volume, clouds/volume/column.glsl)."""
    rank = field_rank(field_fbm(xz, octaves, offsets, tile_size), quantiles)
    return float(column_tau) * column_at_rank(rank, columns)
