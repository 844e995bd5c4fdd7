"""The cloud type (Schneider's Nubis): a number in [0, 1] that gives the marched density its vertical shape.

``RaymarchCloudSettings.cloud_type`` t picks a height profile P(h, t) over the layer (h: height fraction,
0 base, 1 the simulated layer's top): a fast rise from the base (flat bases), a plateau, a fall to 0 of
the form 1 - x² (round tops); the three key types ramp to the ends below and t between them mixes their
breakpoints linearly. Congestus towers above the simulated layer: its fall ends at 1 + TOWER, so types
past cumulus rise above the box (:func:`march_top`: how far the march reaches up); there the columns'
density is the whole column's. The simulation gives each column its coverage c = clamp(m / COLUMN_FULL, 0, 1), m the column's
mean density (the light volume's column integral over the layer's height in cells), and the shaped density

    density(m, h, t) = c' · clamp((P(h, t) - (1 - c')) / c', 0, 1) = clamp(P - (1 - c'), 0, c')
                                         (Nubis' remap(P, 1 - c, 1, 0, 1) · c)

with c' = c^(1 - ANVIL · max(2t - 1, 0) · ramp(h, ANVIL_FROM × fall end)) (congestus widens toward its top). A
column holds cloud from where P first exceeds 1 - c to where it falls below it: a thin column is a low
small cloud, a full one fills the profile, so tops follow the coverage's round outline and bases stay
flat; inside, the density is below the body density (noise.py COVERAGE) wherever P is below 1 (the
tops, thin columns), so the detail noise carves there, through the volume, not only at its edge.
``shaders/clouds/volume/shape.glsl`` is the shader; :func:`type_profile` and :func:`type_density`
are its float64 twins.

Types by region: a :class:`CloudTypeMap` (``RaymarchCloudSettings.type_map``) gives t over the ground in
world metres (stratus over the sea, congestus over the hills), sampled bilinearly at each density sample
(the far field's too), in place of the one ``cloud_type``; :func:`type_at` is its twin.

Shadows of the shape drawn: the renderer that draws with a type publishes it (:class:`DrawnShape`), and
every reader of the column sums (``shaders/clouds/volume/column.glsl``: the ground shadows, the shadow
map, the light shafts, the clouds' light from below) turns each column into the column of the shape
drawn (:func:`typed_column`): a stratus sheet holds 0.2–0.6 of its simulated column, cumulus 0.6–1.4,
a congestus tower up to 4.9 times it, so shadows are as deep as the clouds drawn.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Callable

import numpy as np

from atmos.checks import check_vec
from atmos.plugins.clouds.light.reference import bilinear

CLOUD_TYPES = {"stratus": 0.0, "cumulus": 0.5, "congestus": 1.0}
"""The key types: t of each."""
PROFILES = ((0.05, 0.10, 0.28),   # stratus: (rise end, fall start, fall end) in height fraction: thin, flat
            (0.08, 0.20, 0.70),   # cumulus: flat base, rounded top at about two thirds of the layer
            (0.06, 0.20, 2.50))   # congestus: towers to 1 + TOWER layers, tapering
"""(rise end, fall start, fall end) of each key type, in the order of CLOUD_TYPES."""
TOWER = 1.5           # congestus rises this many layer heights above the simulated layer's top
COLUMN_FULL = 0.35    # a column whose mean density over the layer is this or more is fully covered
ANVIL = 0.5           # the top's coverage exponent falls by up to this much at t = 1 (c^0.5: wider)
ANVIL_FROM = (0.7, 0.95)   # over these fractions of the type's fall end (its top)
TYPE_SUN_STEPS = 2    # with a type the sun march takes this many more steps and ends with 1, not the shading
                      # volume's T (which holds the simulation's own shape: march.glsl sun_transmittance)


def _ramp(x, a, b):
    return np.clip((np.asarray(x, np.float64) - a) / (b - a), 0.0, 1.0)


def type_breakpoints(t) -> np.ndarray:
    """(..., 3): the profile's (rise end, fall start, fall end) at types ``t``, linear between the keys."""
    t = np.clip(np.asarray(t, np.float64), 0.0, 1.0)
    k = np.asarray(PROFILES, np.float64)
    low = k[0] + (k[1] - k[0]) * np.clip(2.0 * t, 0.0, 1.0)[..., None]
    return low + (k[2] - k[1]) * np.clip(2.0 * t - 1.0, 0.0, 1.0)[..., None]


def type_profile(h, t) -> np.ndarray:
    """P(h, t) in [0, 1]: ramp(h, 0, rise end) · (1 - x²), x = ramp(h, fall start, fall end); 0 below the
    base and from the fall end up."""
    h = np.asarray(h, np.float64)
    b = type_breakpoints(t)
    x = _ramp(h, b[..., 1], b[..., 2])
    p = _ramp(h, 0.0, b[..., 0]) * (1.0 - x * x)
    return np.where(h >= 0.0, p, 0.0)


def type_centre(t) -> np.ndarray:
    """The height fraction of the mass centre of a full column of type ``t``'s shape (density P(h, t)):
    ∫ h P dh / ∫ P dh over the rise (linear), the plateau and the fall (1 − x²), in closed form. Stratus
    0.13, cumulus 0.30, congestus 0.97 of the layer: where the sun's ray meets the cloud drawn, for its
    shadow (:func:`centre_rise`)."""
    b = type_breakpoints(t)
    a, top, fall = b[..., 0], b[..., 1], b[..., 2] - b[..., 1]
    moment = a * a / 3.0 + (top * top - a * a) / 2.0 + fall * (2.0 * top / 3.0 + fall / 4.0)
    return moment / (a / 2.0 + (top - a) + 2.0 * fall / 3.0)


def centre_rise(cloud_type, type_map) -> float:
    """Layer heights above the layer's middle at which the sun's columns are read for clouds drawn with
    ``cloud_type``/``type_map``: the mass centre of the type's full column (:func:`type_centre`), of the
    map's mean type with a map (one height for the whole layer: a height following the type would fold
    the shadows wherever the type changes faster than the sun's slant); 0 untyped."""
    if cloud_type is None and type_map is None:
        return 0.0
    return _rise(float(type_map.mean if type_map is not None else cloud_type))


@lru_cache(maxsize=64)
def _rise(t: float) -> float:
    return float(type_centre(t)) - 0.5


def centre_shift(x, z, sun_dir, thickness: float, cloud_type=None, type_map=None,
                 min_sun_height: float = 1e-4) -> np.ndarray:
    """(..., 2) metres (x, z) from points (x, z) of the layer's middle plane along the sun's ray to the
    height :func:`centre_rise` (0 untyped). ``column.glsl`` centre_shift's twin: the sun's columns are read
    there, so a stratus sheet's shadow and a congestus tower's fall where their clouds are, not where the
    layer's middle would put them."""
    x = np.asarray(x, np.float64)
    s = np.asarray(sun_dir, np.float64)
    run = centre_rise(cloud_type, type_map) * thickness / max(float(s[1]), min_sun_height)
    return np.broadcast_to(run * s[[0, 2]], x.shape + (2,)).copy()


def march_top(types) -> float:
    """The height fraction the march must reach for clouds of ``types`` (a number, an array, or None: no
    type; the renderer passes a map's ``highest``): the highest fall end, at least the layer's top (1)."""
    if types is None:
        return 1.0
    return float(max(1.0, type_breakpoints(np.max(types))[2]))


def type_density(m, h, t) -> np.ndarray:
    """The shaped density of a column of mean density ``m`` at height fraction ``h`` and type ``t``."""
    c = np.clip(np.nan_to_num(np.asarray(m, np.float64)) / COLUMN_FULL, 0.0, 1.0)
    t = np.asarray(t, np.float64)
    top = type_breakpoints(t)[..., 2]
    c = c ** (1.0 - ANVIL * np.clip(2.0 * t - 1.0, 0.0, 1.0) * _ramp(h, ANVIL_FROM[0] * top, ANVIL_FROM[1] * top))
    return np.clip(type_profile(h, t) - (1.0 - c), 0.0, c)        # c · remap(P, 1 - c, 1, 0, 1)


MAX_MAP_SIDE = 4096   # texels per side of a CloudTypeMap at most


@dataclass(frozen=True, eq=False)
class CloudTypeMap:
    """Cloud types over the ground: ``types`` (nz, nx), each in [0, 1] (``CLOUD_TYPES``), row j along z and
    column i along x, spread over ``size`` = (sx, sz) metres from the world corner ``origin`` = (x, z), texel
    (i, j)'s centre at origin + ((i + 1/2) sx / nx, (j + 1/2) sz / nz). Read bilinearly between the
    centres and held at the edge texels beyond them (outside the map: its nearest edge). Compared by
    identity: hand a new map to change it (``configure(type_map=...)``)."""
    types: np.ndarray
    origin: tuple = (0.0, 0.0)
    size: tuple = (1.0, 1.0)

    def __post_init__(self):
        t = np.asarray(self.types)
        if t.ndim != 2 or not (1 <= min(t.shape) and max(t.shape) <= MAX_MAP_SIDE):
            raise ValueError(f"CloudTypeMap.types must be a 2D array (nz, nx) of 1..{MAX_MAP_SIDE} texels per "
                             f"side, got shape {t.shape}")
        if t.dtype.kind not in "fiu" or t.dtype == bool:
            raise ValueError(f"CloudTypeMap.types must hold numbers in [0, 1], got dtype {t.dtype}")
        t = t.astype(np.float64)
        if not (np.isfinite(t).all() and t.min() >= 0.0 and t.max() <= 1.0):
            raise ValueError("CloudTypeMap.types must hold finite numbers in [0, 1] (0 stratus, 0.5 cumulus, "
                             f"1 congestus), got values from {np.nanmin(t)} to {np.nanmax(t)}"
                             f"{' and NaN or inf' if not np.isfinite(t).all() else ''}")
        t = np.ascontiguousarray(t.astype(np.float32))
        t.setflags(write=False)
        object.__setattr__(self, "types", t)
        object.__setattr__(self, "highest", float(t.max()))     # the tallest type (march_top): read per frame
        object.__setattr__(self, "mean", float(t.mean()))       # the mean type (centre_rise)
        object.__setattr__(self, "origin", check_vec("CloudTypeMap", "origin", self.origin, 2))
        object.__setattr__(self, "size", check_vec("CloudTypeMap", "size", self.size, 2, "positive"))

    def at(self, x, z) -> np.ndarray:
        """float64 types at world points (x, z) (arrays of one shape): bilinear between texel centres,
        clamped to the edge (shape.glsl cloud_type_at)."""
        nz, nx = self.types.shape
        fx = (np.asarray(x, np.float64) - self.origin[0]) / self.size[0] * nx - 0.5
        fz = (np.asarray(z, np.float64) - self.origin[1]) / self.size[1] * nz - 0.5
        return bilinear(self.types.astype(np.float64), np.stack(np.broadcast_arrays(fz, fx), -1))


TYPED_STEPS = 32     # midpoint samples of a type's profile per column (column_mean)
COLUMN_NODES = (129, 65)   # column_table's nodes: in sqrt(m / COLUMN_FULL), in the type (one at cumulus, 0.5)


def column_mean(m, t) -> np.ndarray:
    """G(m, t): the mean over the layer's height of the shape drawn for a column of mean density ``m`` and
    type ``t`` (the integral of type_density over h in [0, top], top the type's highest point and at least
    the layer's top): the midpoint sum of TYPED_STEPS samples. A typed column sum is ny · G(sum / ny, t)."""
    m, t = np.broadcast_arrays(np.asarray(m, np.float64), np.asarray(t, np.float64))
    dh = np.maximum(type_breakpoints(t)[..., 2], 1.0) / TYPED_STEPS
    total = np.zeros(m.shape)
    for k in range(TYPED_STEPS):
        total += type_density(m, (k + 0.5) * dh, t)
    return dh * total


@lru_cache(maxsize=1)
def column_table() -> np.ndarray:
    """(types, columns) float32, COLUMN_NODES: :func:`column_mean` at sqrt(m / COLUMN_FULL) = i / (columns − 1)
    (G depends on m only through the coverage, flat from COLUMN_FULL on; spaced in the square root, where
    the anvil's c^0.5 is linear) and t = j / (types − 1). ``column.glsl`` reads it (``typed_columns``) with
    4 fetches in place of TYPED_STEPS profile evaluations per column; interpolated it is within 0.4 % of
    G(COLUMN_FULL, t) of the midpoint sum (``tests/test_cloud_type.py``)."""
    nu, nt = COLUMN_NODES
    s = np.linspace(0.0, 1.0, nu)
    table = column_mean((s * s * COLUMN_FULL)[None, :], np.linspace(0.0, 1.0, nt)[:, None]).astype(np.float32)
    table.setflags(write=False)
    return table


def column_lookup(m, t) -> np.ndarray:
    """float64 twin of ``column.glsl``'s table read: :func:`column_table` interpolated bilinearly (in
    float64, on the float32 nodes the GPU holds) at mean densities ``m`` and types ``t``."""
    table = column_table().astype(np.float64)
    nt, nu = table.shape
    m, t = np.broadcast_arrays(np.asarray(m, np.float64), np.asarray(t, np.float64))
    x = np.sqrt(np.clip(np.nan_to_num(m) / COLUMN_FULL, 0.0, 1.0)) * (nu - 1)
    return bilinear(table, np.stack([np.clip(t, 0.0, 1.0) * (nt - 1), x], -1))


def typed_column(sums, x, z, ny: int, cloud_type=None, type_map=None) -> np.ndarray:
    """float64 twin of ``column.glsl`` typed_column: the column sums (summed density over the layer's ``ny``
    cells) of the shape drawn over world points (x, z) for simulated column sums ``sums`` (arrays of one
    shape): ny · G(sums / ny, t) (:func:`column_mean`, read from :func:`column_table`), t the type there
    (:func:`type_at`); ``sums`` itself untyped."""
    sums = np.asarray(sums, np.float64)
    if cloud_type is None and type_map is None:
        return sums
    t = np.broadcast_to(np.asarray(type_at(0.5 if cloud_type is None else cloud_type, type_map, x, z),
                                   np.float64), sums.shape)
    return np.where(sums > 0.0, ny * column_lookup(sums / ny, t), sums)


@dataclass
class DrawnShape:
    """App resource: the cloud type the clouds are drawn with, for the passes that read the columns
    (``column.glsl``: ground shadows, the shadow map, light shafts, the clouds' light from below), so
    their shadows are the shape drawn. ``source``: a zero-argument callable, set by the renderer that
    shapes the density with a type (the ray march), giving (cloud_type, type_map, the map's texture or
    None) as its settings say while it does, else None. It holds the typed columns' table
    (:func:`column_table`) as a texture for those readers while any reads it."""
    source: Callable | None = None
    _columns: object = field(default=None, repr=False)

    def current(self):
        """The source's (cloud_type, type_map, texture), or None: the simulation's own shape."""
        return self.source() if self.source is not None else None

    def columns(self, ctx):
        """:func:`column_table` as an R32F texture on ``ctx`` (``column.glsl``'s ``typed_columns``, read
        with texelFetch), made on first use."""
        if self._columns is None:
            table = column_table()
            self._columns = ctx.texture(table.shape[::-1], 1, table.tobytes(), dtype="f4")
        return self._columns

    def release(self) -> None:
        """Release the table's texture (the clouds' plugin does at its cleanup)."""
        if self._columns is not None:
            self._columns.release()
            self._columns = None


def shape_uniforms(cloud_type, type_map) -> dict:
    """shape.glsl's uniforms: ``cloud_type`` (-1: untyped; with a map, typed whatever it says), whether the
    map gives the type and where it lies."""
    typed = type_map is not None or cloud_type is not None
    t = -1.0 if not typed else float(cloud_type if cloud_type is not None else 0.5)
    box = (0.0, 0.0, 1.0, 1.0) if type_map is None else (
        float(type_map.origin[0]), float(type_map.origin[1]), 1.0 / float(type_map.size[0]), 1.0 / float(type_map.size[1]))
    return {"cloud_type": t, "type_mapped": int(type_map is not None), "type_map_box": box}


def drawn_shape(app) -> DrawnShape:
    """The App's :class:`DrawnShape` (made on first use)."""
    return app.init_resource(DrawnShape)


def type_at(cloud_type, type_map, x, z):
    """The type the march shapes with at world points (x, z): ``type_map``'s where one is given, else
    ``cloud_type`` (None: no type, the simulation's own shape)."""
    return type_map.at(x, z) if type_map is not None else cloud_type
