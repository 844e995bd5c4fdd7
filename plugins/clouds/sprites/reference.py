"""numpy float64 reference of the sprite vertex stage (``shaders/clouds/sprites/sprite.vert``).

Given the densities and transmittances of sets A and B (``[x, y, z]`` arrays, the transmittance at
its own shading resolution), the segments and the uniforms, it returns what every
(instance, vertex) outputs, instance-major like the GPU: the clip position (``CULLED`` for empty
blocks and blocks past the edge), point size, the light (octave weights of the sun's transmittance
averaged over 8 samples spread like the block's mass, log T's slope across the sprite fitted to them, the sky and ground light dimmed by the columns
above and below, the light volume's columns (:mod:`atmos.plugins.clouds.light.columns`): :mod:`atmos.plugins.clouds.light.medium`), the world centre of mass and radius, centre optical depth and coverage; :func:`soft_fade` is the fragment's fade
against the scene depth.
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.clouds.volume.light import sun_source_at
from atmos.plugins.clouds.sprites.particle import centre_tau, footprint, screen_axes
from atmos.plugins.clouds.sprites.segments import unpack
from atmos.phase import Phase
from atmos.plugins.clouds.light.medium import ambient_weights, octave_weights
from atmos.plugins.clouds.light.columns import column_reference, columns_at
from atmos.plugins.clouds.light.grid import SCALES
from atmos.plugins.clouds.light.grid import shading_shape as grid_shape
from atmos.plugins.clouds.light.reference import trilinear

CULLED = np.array([0.0, 0.0, 2.0, 1.0])


HAT_SPREAD = 1.0 / 9.0   # sprite.vert: light samples at the centre of mass ± sqrt(variance + 1/9) cells
MIN_T = 1e-30            # sprite.vert: log T's floor
MAX_SLOPE = 8.0          # sprite.vert: log T's change per half side at most


def toward(k, n: int, c: float, s: int):
    """Block index drawn k-th of ``n`` (size ``s``) along an axis, the camera ``c`` cells from its start:
    each side of the camera walked toward it, the side whose innermost block is farther first."""
    x = np.float32(c) / np.float32(s)
    before = int(np.clip(np.ceil(x - np.float32(0.5)), 0, n))
    after = n - before
    if x >= before:
        return np.where(k < before, k, n - 1 - (k - before))
    return np.where(k < after, n - 1 - k, k - after)


def group_cells(group, level: int, camera) -> np.ndarray:
    """Block origins (in cells, relative to the group) of one group at ``level`` in gl_VertexID order,
    ``camera`` the camera's (x, z) in cells from the group's origin; (n, 2) int32. The outer axis is the
    one the camera is farther off along."""
    s = 1 << level
    nx, nz = group[0] // s, group[1] // s
    cam = np.asarray(camera, np.float32)
    off = np.abs(cam - np.float32(0.5) * np.asarray(group, np.float32))
    k = np.arange(nx * nz)
    if off[0] >= off[1]:
        bx, bz = toward(k // nz, nx, cam[0], s), toward(k % nz, nz, cam[1], s)
    else:
        bx, bz = toward(k % nx, nx, cam[0], s), toward(k // nx, nz, cam[1], s)
    return (np.stack([bx, bz], -1) * s).astype(np.int32)


def column_depth(density, uvw, column_tau: float, shading_shape=None) -> tuple[np.ndarray, np.ndarray]:
    """(tau_up, tau_down) at ``uvw`` (n, 3): ``volume.glsl``'s cloud_columns, the light volume's
    columns (:func:`atmos.plugins.clouds.light.columns.column_reference` at the scale whose grid is ``shading_shape``,
    None: full resolution) sampled trilinearly, times ``column_tau``."""
    shape = np.shape(density)
    scale = next((s for s in SCALES if shading_shape is None or grid_shape(shape, s) == tuple(shading_shape)), None)
    if scale is None:
        raise ValueError(f"shading_shape {tuple(shading_shape)} is no shading grid of {shape} (scales {SCALES})")
    c = column_tau * columns_at(column_reference(density, scale), uvw)
    return c[:, 0], c[:, 1]


def texel_filter(grid, points, weight_bits: int | None = None) -> np.ndarray:
    """Clamp-to-edge trilinear samples of ``grid`` at index-space ``points`` (..., 3): exact, as
    ``volume.glsl`` texel_trilinear filters; with ``weight_bits`` a model of a texture unit's filter
    (float32 coordinates, sub-texel weights rounded to that many bits: 8 on a machine with an NVIDIA GPU)."""
    if weight_bits is None:
        return trilinear(grid, points)
    p = np.clip(np.asarray(points, np.float32).astype(np.float64), 0, np.array(np.shape(grid)) - 1)
    i0, step = np.floor(p), 2.0 ** int(weight_bits)
    return trilinear(grid, i0 + np.round((p - i0) * step) / step)


def shifted(volume: np.ndarray, shift) -> np.ndarray:
    """``volume`` (nx, ny, nz) read at cell ``c + shift`` for every cell c, zero past its edge
    (set A on set B's grid: :attr:`~atmos.plugins.clouds.CloudSets.a_shift`)."""
    out = np.zeros_like(volume)
    src, dst = [], []
    for n, s in zip(volume.shape, shift):
        src.append(slice(max(s, 0), min(n, n + s)))
        dst.append(slice(max(-s, 0), min(n, n - s)))
    out[tuple(dst)] = volume[tuple(src)]
    return out


def sprite_vertices(density_a, density_b, trans_a, trans_b, t: float, segments, uniforms: dict, view_proj,
                    light: dict, a_shift=(0, 0, 0), weight_bits: int | None = None, ground_sun: float = 1.0) -> dict:
    """Arrays over the vertices of every segment (gi, j, gk, packed level and span), in order: ``position`` (n, 4),
    ``size``, ``octaves`` (n, 4), ``ambient`` (n, 3), ``sun`` (n, 3: the sun's source at its height), ``center`` (n, 3), ``radius``, ``tau``, ``stretch``, ``coverage``,
    ``visible``. ``trans_a``/``trans_b`` None: no shading (T = 1). ``light``: the light uniforms
    (:func:`atmos.plugins.clouds.volume.light.light_uniforms`). ``a_shift``: A's cell for B's cell c is
    c + a_shift (zero past A's edge for the cell sums; clamp-to-edge for the sampled light, as the GPU).
    ``weight_bits``: the sun's transmittance filtered as a texture unit with that many bits of sub-texel
    weight would (:func:`texel_filter`; None: exactly, as sprite.vert). ``ground_sun``: the ground's
    mean sun transmittance G (:mod:`atmos.plugins.clouds.light.ground`)."""
    u = uniforms
    shape = np.array(u["volume_shape"])
    gx, gz = u["group_size"]
    seg = np.asarray(segments, np.int64)
    shift = np.array([int(v) for v in a_shift])
    a64, b64 = np.asarray(density_a, np.float64), np.asarray(density_b, np.float64)
    d_full = shifted(a64, shift) * (1.0 - t) + b64 * t
    levels, spans_x, spans_z = unpack(seg[:, 3])
    padded = np.pad(d_full, [(0, 1 << int(levels.max(initial=0)))] * 3)   # cells past the edge are empty
    cells, sums, firsts, seconds, spans = [], [], [], [], []
    camera = np.asarray(u["camera_cell"], np.float32)
    for (gi, j, gk, _), level, sx, sz in zip(seg, levels, spans_x, spans_z):
        s = 1 << level
        local = group_cells((gx * sx, gz * sz), level, camera[[0, 2]] - np.float32([gi * gx, gk * gz]))
        origin = np.stack([gi * gx + local[:, 0], np.full(len(local), j * s), gk * gz + local[:, 1]], -1)
        offsets = np.stack(np.meshgrid(*[np.arange(s)] * 3, indexing="ij"), -1).reshape(-1, 3)
        idx = np.minimum(origin[:, None, :] + offsets[None], np.array(padded.shape) - 1)
        mass = padded[idx[..., 0], idx[..., 1], idx[..., 2]]
        sums.append(mass.sum(1))
        firsts.append(mass @ (offsets + 0.5))
        seconds.append(mass @ (offsets + 0.5) ** 2)
        cells.append(origin)
        spans.append(np.full(len(local), s))
    c = np.concatenate(cells)
    total = np.concatenate(sums)
    s = np.concatenate(spans).astype(np.float64)
    inside = (c < shape).all(-1)
    visible = inside & (total > 0)
    weight = np.maximum(total, 1e-300)[:, None]
    mean = np.concatenate(firsts) / weight
    cells_var = np.maximum(np.concatenate(seconds) / weight - mean ** 2, 0.0)
    spread = np.sqrt(cells_var + HAT_SPREAD)
    center = c + np.where(visible[:, None], mean, 0.5 * s[:, None])     # the block's centre of mass
    a_ms, b_ms, _ = light["ms_octaves"]
    g_mean = Phase(*light["phase_lobes"]).mean_cosine
    uvw = center / shape
    uvw_a = (center + shift) / shape
    grid = None if trans_a is None else np.shape(trans_a)
    (up_a, down_a), (up_b, down_b) = (column_depth(d, w, light["column_tau"], grid) for d, w in ((a64, uvw_a), (b64, uvw)))
    up, down = (1.0 - t) * up_a + t * up_b, (1.0 - t) * down_a + t * down_b
    octaves, slope = np.zeros((len(c), 4)), np.zeros((len(c), 3))
    for side in np.stack(np.meshgrid(*[(-1.0, 1.0)] * 3, indexing="ij"), -1).reshape(-1, 3):
        tap = center + side * spread
        if trans_a is None:
            T = np.ones(len(c))
        else:
            tex = np.array(np.shape(trans_a))
            T = (texel_filter(np.asarray(trans_a, np.float64), (tap + shift) / shape * tex - 0.5, weight_bits) * (1 - t)
                 + texel_filter(np.asarray(trans_b, np.float64), tap / shape * tex - 0.5, weight_bits) * t)
        octaves += octave_weights(T, a_ms, b_ms) / 8.0
        slope += side * np.log(np.maximum(T, MIN_T))[:, None]
    world = np.asarray(u["layer_min"]) + center * np.asarray(u["cell_size"])
    ray = world - np.asarray(u["camera_pos"], np.float64)
    w = ambient_weights(up, down, g_mean, light["albedo"], ray[:, 1] / np.linalg.norm(ray, axis=1))
    sky = np.asarray(light["sky_source"])
    ground = np.asarray(light["ground_sky_source"]) + ground_sun * np.asarray(light["ground_sun_source"])
    ambient = 2.0 * (w[:, :1] * sky + w[:, 1:] * ground)
    clip = np.concatenate([world, np.ones((len(c), 1))], 1) @ np.asarray(view_proj, np.float64).T
    diameter = s * u["base_diameter"]
    axis_x, axis_y, stretch = screen_axes(ray, u["camera_right"], u["camera_up"], u["near"])
    conic, k, det = footprint(cells_var, u["cell_size"], 0.5 * diameter, axis_x, axis_y)
    px = stretch * diameter * u["pixel_scale"] / np.maximum(clip[:, 3], 1e-6)
    g = slope / (8.0 * spread * np.asarray(u["cell_size"], np.float64))      # log T's gradient, 1/m
    h = np.clip((stretch * 0.5 * diameter)[:, None] * np.stack([g @ u["camera_right"], g @ u["camera_up"]], -1),
                -MAX_SLOPE, MAX_SLOPE)
    cov = np.stack([conic[:, 2], -conic[:, 1], conic[:, 0]], -1) * det[:, None]      # xx, xy, yy in half sides
    half_var = 0.5 * (cov[:, 0] * h[:, 0] ** 2 + 2.0 * cov[:, 1] * h[:, 0] * h[:, 1] + cov[:, 2] * h[:, 1] ** 2)
    near, far = u["near"], u["far"]                 # depth-tested at its front: the centre a radius nearer
    front = np.maximum(clip[:, 3] - 0.5 * diameter, near)
    ndc = np.minimum((far + near) / (far - near) - 2.0 * far * near / ((far - near) * front), 1.0)
    clip = np.concatenate([clip[:, :2], (ndc * clip[:, 3])[:, None], clip[:, 3:]], 1)
    return {"position": np.where(visible[:, None], clip, CULLED),
            "size": np.where(visible, np.clip(px, 1.0, u["max_point_size"]), 1.0),
            "octaves": np.where(visible[:, None], octaves, 0.0),
            "slope": np.where(visible[:, None], np.concatenate([h, half_var[:, None]], 1), 0.0),
            "ambient": np.where(visible[:, None], ambient, 0.0),
            "sun": np.where(visible[:, None], sun_source_at(light["sun_sources"], uvw[:, 1]), 0.0),
            "center": np.where(visible[:, None], world, 0.0),
            "radius": np.where(visible, 0.5 * diameter, 0.0),
            "tau": np.where(visible, centre_tau(u["tau_scale"] * total, 0.5 * diameter, det, k, stretch), 0.0),
            "stretch": np.where(visible, stretch, 1.0),
            "conic": np.where(visible[:, None], conic, [1.0, 0.0, 1.0]),
            "falloff": np.where(visible, k, 1.0),
            "coverage": np.where(visible, np.clip(px, 0.0, 1.0) ** 2 *
                                 np.clip((clip[:, 3] - u["near"]) / np.maximum(diameter, 1e-30), 0.0, 1.0), 0.0),
            "visible": visible}


def soft_fade(scene_depth, sprite_depth, radius, near: float, far: float) -> np.ndarray:
    """The soft-particle factor of ``sprite.frag``: clamp(1/2 + (scene view depth − sprite view depth) /
    (2 radius), 0, 1) — the share of the sprite's depth span in front of the surface — ``scene_depth`` the window depth under the fragment (off screen: :func:`.offscreen_reference.far_depth`
    of the frame's), ``sprite_depth`` the sprite centre's view depth (its clip w)."""
    d = np.asarray(scene_depth, np.float64)
    scene = near / ((1.0 - d) + d * (near / far))
    return np.clip(0.5 + 0.5 * (scene - np.asarray(sprite_depth, np.float64)) / np.asarray(radius, np.float64),
                   0.0, 1.0)
