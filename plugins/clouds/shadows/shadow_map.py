"""The cloud shadow map: the sun's optical depth through the clouds baked once per frame, read with one fetch.

``sun_optical_depth`` (:mod:`.reference`, ``clouds/volume/column.glsl``) is ``above(p.y) · T(q)``: ``q``
the point's projection along the sun onto the layer's middle plane, ``above`` the fraction of the
layer over the point, and ``T(q) = extinction · column(q') · fade(q') + field_tau · far(q') · (1 − fade(q'))``,
``q'`` where the sun's ray through ``q`` meets the height of the mass centre of the cloud type drawn
(``shape.centre_shift``; ``q`` itself untyped), a function of ``q`` alone. So the map stores, over the middle plane (the image plane of a parallel projection along the sun),
the two columns per unit extinction (rg16f: volume, far field); a lookup projects the point as the
exact form does, reads both with one bilinear fetch, weights them by the caller's extinctions and
multiplies by ``above``: the height handling is exact, the only errors are the map's sampling and
format.

Grid: one ``N × 2N`` image (``N = MAP_SIZE``), rows [0, N) the near cascade, [N, 2N) the far one.
Near: ``r`` map texels per volume cell (the largest integer fitting the volume and a margin, at most
NEAR_RATIO), texel centres on the column centres, so the piecewise-bilinear column sums are reproduced
exactly (only the edge fade, a cloud type's shape of the sum and the far field between texels are
interpolated); it uses the first ``near`` texels of its rows and columns (the rest hold 0 and are never
read), so a small volume bakes no more texels than it needs. Far: centred on the camera's own
projection, ``FAR_REACH × camera.far`` each way (lookups past it clamp to its edge): the far field,
on a grid warped per axis, ``offset = K sinh(FAR_WARP (j − c) / c)`` (``c = (N − 1) / 2``), so its
texels are ``sinh(w) / w`` (3.3) times finer than an even grid's around the camera, where shadows and
shafts are seen large, and ``w coth(w)`` (3.0) times coarser at its edge; a lookup inverts it with one
``asinh``, the fetch stays one bilinear tap (a separable warp keeps the grid rectilinear).
Format: rg16f, relative rounding 2⁻¹¹, so ``|Δ exp(−τ)| ≤ τ e^{−τ} 2⁻¹¹ ≤ 2⁻¹¹/e``
(1.8e-4, far below the 8-bit output step); sums of up to thousands of cells fit its range (65504).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from atmos.graph import ComputePass, TextureDesc
from atmos.gpu.uniforms import write_uniforms
from atmos.plugins.clouds.far_field.layer import column_tau
from atmos.plugins.clouds.volume.column import column_uniforms
from atmos.plugins.clouds.volume.sets import CLOUD_SETS, FAR_FIELD

SHADOW_MAP = "cloud_shadow_map"        # rg16f (N, 2N): near and far cascades of the sun's columns
SHADOW_SPACE = "cloud_shadow_space"    # the map's ShadowMapSpace (imported; the bake updates it)
MAP_SIZE = 1024                        # N: texels per cascade side
FAR_REACH = 1.25                       # the far cascade reaches this × camera.far from the camera's projection
MIN_SUN_HEIGHT = 1e-4                  # as column.glsl's
NEAR_RATIO = 8                         # the near cascade's map texels per volume cell at most (a small volume's)
FAR_WARP = 3.0                         # w: the far cascade's warp (offset = K sinh(w u), u in [-1, 1])
FORMAT_ERROR = 2.0 ** -11              # rg16f's relative rounding (half an ulp of an 11-bit significand)


@dataclass
class ShadowMapSpace:
    """Where the map lies: ``cascades`` (2, 4): the near cascade's volume texel coordinate of its texel
    (0, 0) and its volume texels per map texel (x, z); the far one's centre (the camera's projection, in
    volume texel coordinates) and its warp's scale K per axis (volume texels: texel j lies at
    ``centre + K sinh(warp (j − c) / c)``); ``near`` the near cascade's texels per side in use; the
    layer's heights and placement."""
    size: int = MAP_SIZE
    cascades: np.ndarray = field(default_factory=lambda: np.zeros((2, 4)))
    lo: np.ndarray = field(default_factory=lambda: np.zeros(3))
    cell: np.ndarray = field(default_factory=lambda: np.ones(3))
    shape: tuple = (1, 1, 1)
    frame: int = -1                    # bumped by every bake
    near: int = MAP_SIZE               # texels per side of the near cascade in use (<= size)
    sun: np.ndarray = field(default_factory=lambda: np.array([0.0, 1.0, 0.0]))   # the sun baked for (unit)
    warp: float = FAR_WARP

    @property
    def far_centre_index(self) -> float:
        """c: the far cascade's centre texel index, (N − 1) / 2."""
        return 0.5 * (self.size - 1)

    def far_offsets(self, j) -> np.ndarray:
        """Volume texel offsets (..., 2) of the far cascade's texel indices ``j`` (..., 2) from its centre."""
        c = self.far_centre_index
        return self.cascades[1, 2:] * np.sinh(self.warp * (np.asarray(j, np.float64) - c) / c)

    def far_index(self, v) -> np.ndarray:
        """The far cascade's continuous texel index (..., 2) of volume texel coordinates ``v`` (unclamped)."""
        c = self.far_centre_index
        return c + c / self.warp * np.arcsinh((np.asarray(v, np.float64) - self.cascades[1, :2]) / self.cascades[1, 2:])

    def plane_texel(self, points, sun_dir) -> np.ndarray:
        """Volume texel coordinates (..., 2) where a lookup at world ``points`` (..., 3) reads: their
        projection along the sun (unit ``sun_dir``) onto the layer's middle plane, as shadow_map.glsl."""
        p, s = np.asarray(points, np.float64), np.asarray(sun_dir, np.float64)
        run = np.maximum(self.mid - p[..., 1], 0.0) / max(s[1], MIN_SUN_HEIGHT)
        return (p[..., [0, 2]] + run[..., None] * s[[0, 2]] - self.lo[[0, 2]]) / self.cell[[0, 2]] - 0.5

    def read_at(self, v) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Where a lookup at volume texel coordinates ``v`` (..., 2) reads, as shadow_map.glsl: (the map
        texel index (..., 2) in its cascade, clamped; whether that is the near cascade (...,); the width
        of the map cell it falls in, in volume texels (..., 2))."""
        v = np.asarray(v, np.float64)
        c = self.cascades
        j = (v - c[0, :2]) / c[0, 2:]
        near = np.all((j >= 0.0) & (j <= self.near - 1.0), axis=-1)
        far = np.clip(self.far_index(v), 0.0, self.size - 1.0)
        j = np.where(near[..., None], j, far)
        i0 = np.minimum(np.floor(far), self.size - 2)
        width = np.where(near[..., None], c[0, 2:], self.far_offsets(i0 + 1) - self.far_offsets(i0))
        return j, near, width

    @property
    def mid(self) -> float:
        return float(self.lo[1] + 0.5 * self.shape[1] * self.cell[1])

    @property
    def thickness(self) -> float:
        return float(self.shape[1] * self.cell[1])

    def matches(self, layout) -> bool:
        """Whether the map was baked for ``layout`` (a consumer with its own placement reads the exact columns)."""
        return (tuple(layout.shape) == tuple(self.shape) and np.array_equal(layout.lo, self.lo)
                and np.array_equal(np.asarray(layout.cell, np.float64), self.cell))

    def uniforms(self, program, extinction: float, field_tau: float = 0.0) -> None:
        """Set ``clouds/shadows/shadow_map.glsl``'s uniforms (the map itself is bound by the caller)."""
        c, centre = self.cascades, self.far_centre_index
        lookup = np.array([[c[0, 0], c[0, 1], 1.0 / c[0, 2], 1.0 / c[0, 3]], [c[1, 0], c[1, 1], 1.0 / c[1, 2], 1.0 / c[1, 3]],
                           [centre / self.warp, centre, 0.0, 0.0]], "f4")
        write_uniforms(program, shadow_cascades=lookup.tobytes(),
                       shadow_plane=(float(self.lo[0]), float(self.lo[2]), 1.0 / self.cell[0], 1.0 / self.cell[2]),
                       shadow_heights=(self.mid, float(self.lo[1]) + self.thickness, 1.0 / self.thickness,
                                       float(self.near - 1)),
                       shadow_weights=(float(extinction), float(field_tau)))


def near_ratio(shape, size: int, pad: int) -> int:
    """Map texels per volume cell of the near cascade: the largest integer up to NEAR_RATIO with the
    volume and ``pad`` cells each side within ``size`` texels (1 when even that does not fit)."""
    return max(1, min(NEAR_RATIO, (size - 1) // (max(shape[0], shape[2]) + 1 + 2 * pad)))


def shadow_space(layout, camera_position, sun_dir, camera_far: float, size: int = MAP_SIZE,
                 reach: float = FAR_REACH, space: ShadowMapSpace | None = None) -> ShadowMapSpace:
    """The map's cascades for ``layout`` (the volume's placement) seen from ``camera_position`` with the
    sun toward ``sun_dir`` (unit): near on the volume's columns, far around the camera's projection."""
    space = space or ShadowMapSpace()
    lo, cell = np.asarray(layout.lo, np.float64), np.asarray(layout.cell, np.float64)
    shape = tuple(map(int, layout.shape))
    space.size, space.lo, space.cell, space.shape = int(size), lo, cell, shape
    space.sun = np.asarray(sun_dir, np.float64).copy()
    mid = lo[1] + 0.5 * shape[1] * cell[1]
    cam, s = np.asarray(camera_position, np.float64), np.asarray(sun_dir, np.float64)
    q = cam[[0, 2]] + max(mid - cam[1], 0.0) / max(s[1], MIN_SUN_HEIGHT) * s[[0, 2]]
    half = reach * float(camera_far)
    vq = (q - lo[[0, 2]]) / cell[[0, 2]] - 0.5                   # the camera's projection, volume texels
    scale = half / np.sinh(space.warp) / cell[[0, 2]]             # K per axis, volume texels
    c = space.far_centre_index
    lo_v, hi_v = np.array([-0.5, -0.5]), np.array([shape[0], shape[2]], np.float64) - 0.5
    pad = 1
    for _ in range(3):      # far lookups past the near cascade never reach the volume: pad > the far texels there
        reach_v = np.maximum(np.abs(lo_v - pad - vq), np.abs(hi_v + pad - vq))
        far_step = scale * space.warp / c * np.sqrt(1.0 + (reach_v / scale) ** 2)    # dv/dj = K w/c cosh
        pad = max(pad, 1 + math.ceil(max(far_step)))
    r = near_ratio(shape, size, pad)
    space.near = min(int(size), r * (max(shape[0], shape[2]) + 1 + 2 * pad) + 1)
    centre = (np.array([shape[0], shape[2]], np.float64) - 1.0) / 2.0
    near0 = np.floor(centre - (space.near - 1) / (2.0 * r))             # integer: texel centres on columns
    space.cascades = np.array([[near0[0], near0[1], 1.0 / r, 1.0 / r],
                               [vq[0], vq[1], scale[0], scale[1]]])
    return space


class CloudShadowMapPass(ComputePass):
    """Bakes "cloud_shadow_map" (phase shadows, before its readers) from "cloud_sets" and, when imported,
    the far field; culled when nothing reads it."""
    name = "cloud_shadow_map"
    phase = "shadows"
    compute = "clouds/shadows/bake.comp"

    def __init__(self, graph, size: int = MAP_SIZE):
        super().__init__()
        self.graph, self.size = graph, int(size)
        self.space = ShadowMapSpace(size=self.size)

    def far_field(self) -> bool:
        return self.graph.imports(FAR_FIELD)

    def defines(self) -> dict:
        return {"CLOUD_FAR_FIELD": 1} if self.far_field() else {}

    def setup_key(self) -> tuple:
        return (self.graph.imports(CLOUD_SETS), self.far_field(), self.size)

    def setup(self, builder) -> None:
        if not self.graph.imports(CLOUD_SETS):
            return
        builder.create(SHADOW_MAP, TextureDesc((self.size, 2 * self.size), components=2, dtype="f2", storage=True),
                       access="storage")
        builder.read(CLOUD_SETS)
        if self.far_field():
            builder.read(FAR_FIELD)

    def execute(self, frame) -> None:
        from atmos.lighting import unit_sun
        view, p = frame.view, self.program
        sim = frame.resource(CLOUD_SETS)
        layout = sim.layout()
        sun = unit_sun(view.sun.direction)
        sun = np.array([0.0, 1.0, 0.0]) if sun is None else sun
        shadow_space(layout, view.camera.position, sun, view.camera.far, self.size, space=self.space)
        self.space.frame += 1
        layer = frame.resource(FAR_FIELD) if frame.declares(FAR_FIELD) else None
        if layer is not None:                   # first: its measure dispatches programs of its own
            layer.prepare(view, sim)
        column_uniforms(p, sim, layout, 1.0)
        if layer is not None:
            layer.use(p, view, sim)
        c = self.space.far_centre_index
        cascades = np.empty((3, 4), "f4")
        cascades[:2], cascades[2] = self.space.cascades, (self.space.warp / c, c, 0.0, 0.0)
        write_uniforms(p, cascades=cascades.tobytes(), near_size=self.space.near,
                       bake_sun=tuple(map(float, sun)))
        image = frame.image(SHADOW_MAP)
        frame.dispatch(p, self.groups(image.size), images={"shadow_map": image})


def shadow_map_pass(graph) -> CloudShadowMapPass:
    """The graph's CloudShadowMapPass, added (with its SHADOW_SPACE import) by the first reader."""
    p, made = graph.shared_pass(CloudShadowMapPass, lambda: CloudShadowMapPass(graph))
    if made:
        graph.import_resource(SHADOW_SPACE, p.space)
    return p


def read_shadow_map(builder, graph) -> None:
    """Declare, in a pass's setup, what :func:`use_shadow_map` with :func:`cloud_extinctions` reads: the
    map, its space, the clouds' sets and, when the graph imports one, the far field (its column's depth)."""
    builder.read(SHADOW_MAP)
    builder.read(SHADOW_SPACE)
    builder.read(CLOUD_SETS)
    if graph.imports(FAR_FIELD):
        builder.read(FAR_FIELD)


def cloud_extinctions(frame) -> tuple[float, float]:
    """(the volume's extinction per summed cell, the far field's column optical depth: 0 without one) in
    a pass that declared CLOUD_SETS (and FAR_FIELD): the clouds' own, as the ground shadows and the
    clouds' light take them."""
    sim = frame.resource(CLOUD_SETS)
    return float(sim.settings.sigma), column_tau(frame.resource(FAR_FIELD).settings, sim) if frame.declares(FAR_FIELD) else 0.0


def use_shadow_map(frame, program, extinction: float, field_tau: float = 0.0) -> None:
    """Bind the map and set shadow_map.glsl's uniforms in a pass that declared SHADOW_MAP and SHADOW_SPACE."""
    from atmos.gpu.uniforms import bind_textures
    bind_textures(program, cloud_shadow_map=frame.resource(SHADOW_MAP))
    frame.resource(SHADOW_SPACE).uniforms(program, extinction, field_tau)


# float64 reference ------------------------------------------------------------------------------------

def texel_positions(space: ShadowMapSpace) -> np.ndarray:
    """(2N, N, 2) volume texel coordinates (x, z) of every map texel centre, rows as the image's."""
    n = space.size
    j = np.arange(n, dtype=np.float64)
    out = np.empty((2 * n, n, 2))
    c = space.cascades
    out[:n, :, 0] = c[0, 0] + j[None, :] * c[0, 2]
    out[:n, :, 1] = c[0, 1] + j[:, None] * c[0, 3]
    far = space.far_offsets(np.stack([j, j], -1)) + c[1, :2]
    out[n:, :, 0] = far[None, :, 0]
    out[n:, :, 1] = far[:, None, 1]
    return out


def bake_reference(space: ShadowMapSpace, sums_a, sums_b, t: float, layout, a_shift=(0, 0, 0),
                   edge_fade: float = 0.0, far=None, cloud_type=None, type_map=None) -> np.ndarray:
    """The map (2N, N, 2) in float64: per texel (column sum × fade, far(xz) × (1 − fade)); ``far``: None
    or the far field's column per unit optical depth at world xz (..., 2); both columns the shape drawn
    with ``cloud_type``/``type_map`` (:func:`~atmos.plugins.clouds.volume.shape.typed_column`)."""
    from atmos.plugins.clouds.shadows.reference import shifted, zero_border_bilinear
    from atmos.plugins.clouds.volume.edge import edge_weight
    from atmos.plugins.clouds.volume.shape import centre_shift, typed_column
    v = texel_positions(space)
    sums = (1.0 - t) * shifted(np.asarray(sums_a, np.float64), a_shift) + t * np.asarray(sums_b, np.float64)
    shape = np.array([space.shape[0], space.shape[2]], np.float64)
    out = np.zeros(v.shape)
    xz = space.lo[[0, 2]] + (v + 0.5) * space.cell[[0, 2]]
    shift = centre_shift(xz[..., 0], xz[..., 1], space.sun, space.thickness, cloud_type, type_map, MIN_SUN_HEIGHT)
    v, xz = v + shift / space.cell[[0, 2]], xz + shift       # where the sun's ray meets the shape drawn
    fade = edge_weight((v + 0.5) / shape, edge_fade)
    ny, x, z = space.shape[1], xz[..., 0], xz[..., 1]
    out[..., 0] = typed_column(zero_border_bilinear(sums, v), x, z, ny, cloud_type, type_map) * fade
    if far is not None:
        out[..., 1] = typed_column(far(xz), x, z, ny, cloud_type, type_map) * (1.0 - fade)
    out[space.near:space.size] = 0.0                # the near cascade's texels not in use: its last rows,
    out[:space.size, space.near:] = 0.0             # and its last columns
    return out


def lookup_reference(space: ShadowMapSpace, baked: np.ndarray, points, sun_dir, weights) -> np.ndarray:
    """shadow_map.glsl in float64: the optical depth (...,) at world ``points`` (..., 3) from map ``baked``
    (2N, N, 2), with ``weights`` (volume extinction, far field's column optical depth)."""
    p, s = np.asarray(points, np.float64), np.asarray(sun_dir, np.float64)
    n = space.size
    v = space.plane_texel(p, s)
    above = np.clip((space.lo[1] + space.thickness - p[..., 1]) / space.thickness, 0.0, 1.0)
    j, near, _ = space.read_at(v)
    row0 = np.where(near, 0, n)
    i0 = np.minimum(np.floor(j).astype(np.int64), n - 2)
    f = j - i0
    x0, z0 = i0[..., 0], i0[..., 1] + row0
    col = ((1 - f[..., 1:]) * ((1 - f[..., :1]) * baked[z0, x0] + f[..., :1] * baked[z0, x0 + 1])
           + f[..., 1:] * ((1 - f[..., :1]) * baked[z0 + 1, x0] + f[..., :1] * baked[z0 + 1, x0 + 1]))
    return (col @ np.asarray(weights, np.float64)) * above
