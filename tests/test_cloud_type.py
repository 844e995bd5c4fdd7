"""The ray march's cloud type (plugins/clouds/volume/shape.py): the shader's profile and shaped density
against their float64 twins on fresh random inputs, the march with each type (and with types by region)
against its reference, the profiles' shapes, skipping with a type, and the settings' checks."""
import numpy as np
import pytest

from atmos.camera import Camera
from atmos.plugins.clouds import CloudsPlugin
from atmos.plugins.clouds.light.diffusion import DIFFUSION, read_field
from atmos.plugins.clouds.light.ground import ground_sun_of
from atmos.plugins.clouds.raymarch import RaymarchCloudSettings, RaymarchCloudsPlugin
from atmos.plugins.clouds.raymarch.reference import march_reference
from atmos.plugins.clouds.volume.shape import (CLOUD_TYPES, COLUMN_FULL, TOWER, CloudTypeMap, march_top, type_density,
                                                 type_profile)
from fullscreen_probe import run_fullscreen
from atmos.plugins.clouds.volume.light import layer_sun, sun_source_at
from test_cloud_raymarch import BY_ALTITUDE, DAY, aim, linear, scene, shading_volume

F32 = 2.0 ** -23      # float32's unit roundoff (the probe computes in float32 from float32 inputs)


def test_the_shaders_profile_and_density_match_their_float64_twins(gpu, ctx, rng):
    w, h = 64, 32
    m = rng.uniform(-0.1, 1.2, (h, w))
    m[:, :8] = rng.uniform(0.0, 0.02, (h, 8))                       # thin columns: the smallest coverages
    points = np.stack([m, rng.uniform(-0.1, 2.7, (h, w)), rng.uniform(0.0, 1.0, (h, w))], -1)   # towers to 2.5
    points[0, :3, 2] = list(CLOUD_TYPES.values())                   # the key types exactly
    points = points.astype(np.float32)
    out = run_fullscreen(gpu, "test/type_probe.frag", (w, h), inputs={"probe_points": points}, nearest=True)
    mm, hh, tt = (points[..., k].astype(np.float64) for k in range(3))
    # the remaps divide by breakpoint spans >= 0.02 and square once: a few float32 roundings each scaled by
    # at most 1 / 0.02; the anvil's pow (c^e, e in [0.5, 1]) adds its own few ulps relative
    assert np.abs(out[..., 0] - type_profile(hh, tt)).max() < 64 * F32 / 0.02
    assert np.abs(out[..., 1] - type_density(mm, hh, tt)).max() < 64 * F32 / 0.02 + 1e-5
    assert (type_density(mm, hh, tt) > 0.1).mean() > 0.2, "the inputs must reach the shaped density"


def test_the_profiles_have_the_types_shapes():
    h = np.linspace(0.0, 1.0, 1001)
    stratus, cumulus, congestus = (type_profile(h, t) for t in CLOUD_TYPES.values())
    top = {name: h[type_profile(h, t) > 0].max() for name, t in CLOUD_TYPES.items()}
    assert top["stratus"] < 0.3 < top["cumulus"] < 0.75 < 0.95 < top["congestus"], top
    # congestus towers above the simulated layer, to 1 + TOWER of its height; the others stay inside it
    high = np.linspace(0.0, 3.0, 3001)
    assert high[type_profile(high, 1.0) > 0].max() == pytest.approx(1 + TOWER, abs=2e-3)
    assert march_top(CLOUD_TYPES["congestus"]) == 1 + TOWER and march_top(0.5) == march_top(None) == 1.0
    assert march_top(np.array([0.1, 0.75])) == pytest.approx(0.5 * (0.7 + 1 + TOWER))
    for p in (stratus, cumulus, congestus):                 # flat bases: full density within 8 % of the base
        assert p[0] == 0.0 and p[h <= 0.08].max() == 1.0 and np.all(p <= 1.0) and np.all(p >= 0.0)
    # a thin column is a smaller cloud of the same type: it holds cloud over less height, never more
    for name, t in CLOUD_TYPES.items():
        thin, full = type_density(0.3 * COLUMN_FULL, h, t), type_density(COLUMN_FULL, h, t)
        assert np.all(thin <= full) and 0 < (thin > 0).sum() < (full > 0).sum(), name
        assert np.all(thin <= 0.3 + 1e-12), "a column's density is at most its coverage"
    # congestus widens near its top (the anvil): there more of the columns hold cloud than its profile gives
    c = np.linspace(0.0, 1.0, 1001)
    for y in (0.85 * (1 + TOWER), 0.9 * (1 + TOWER)):
        no_anvil = np.clip(type_profile(y, 1.0) - (1.0 - c), 0.0, c)
        anvil = type_density(c * COLUMN_FULL, y, 1.0)
        assert np.all(anvil >= no_anvil) and (anvil > 0).mean() > (no_anvil > 0).mean() + 0.05, y
    assert np.allclose(type_density(c * COLUMN_FULL, 0.6, 1.0), np.clip(type_profile(0.6, 1.0) - 1.0 + c, 0.0, c),
                       rtol=0.0, atol=1e-12), "below the anvil: the profile alone"


def random_volume(rng, shape=(16, 6, 16)):
    """A few boxes of random density and height: columns from thin to full."""
    d = np.zeros(shape, np.float32)
    for _ in range(6):
        x, z = rng.integers(0, shape[0] - 4), rng.integers(0, shape[2] - 4)
        y0 = rng.integers(0, shape[1] - 1)
        d[x:x + rng.integers(2, 6), y0:y0 + rng.integers(1, shape[1] - y0 + 1), z:z + rng.integers(2, 6)] = rng.uniform(0.3, 1.0)
    return d


@pytest.mark.parametrize("name", list(CLOUD_TYPES))
def test_the_march_with_each_type_matches_its_float64_reference(gpu, ctx, rng, name):
    d = random_volume(rng)
    app = scene(gpu, d, DAY, empty_space_skipping=False, min_transmittance=0.0, steps=128, step_growth=0.002,
                cloud_type=CLOUD_TYPES[name])
    # the columns are half floats (relative 2^-11) and the shaped density moves by at most as much as the
    # coverage m / COLUMN_FULL (clamp(P - 1 + c, 0, c)): up to 2^-11 / COLUMN_FULL = 1.4e-3 of density, so
    # alpha and colour ~1e-3 (measured: colour 5e-4..6e-4, alpha p99.5 4e-4..6e-4)
    march_against_reference(gpu, app, d, colour=0.003, coverage=0.002)
    app.close()


def march_against_reference(gpu, app, d, colour: float, coverage: float, sun=DAY) -> dict:
    """The scene's march of ``d`` seen from the test's view against march_reference: colour relative RMSE
    below ``colour``, alpha's 99.5th percentile off it below ``coverage``, only rays grazing the box's faces
    further off. Returns the reference."""
    cam = aim(app, (80.0, 520.0, -220.0), target=(160.0, 470.0, 200.0))
    image = linear(app)
    sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation.sets()
    settings = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin)).settings
    ref = march_reference(d, shading_volume(sim), sim.settings, settings, sim.layout(), cam, sun, gpu.size,
                          field=read_field(sim.a[DIFFUSION]), ground_sun=ground_sun_of(sim))
    assert (ref["alpha"] > 0.05).mean() > 0.02, "the view must see the clouds"
    light = ref["light"]
    rmse = np.sqrt(np.mean((image[..., :3] - light) ** 2)) / np.sqrt(np.mean(light ** 2))
    assert rmse < colour, f"colour off the reference: relative RMSE {rmse:.4f}"
    off = np.abs(image[..., 3] - ref["alpha"])
    assert np.percentile(off, 99.5) < coverage, "coverage off the reference"
    assert (off > 0.02).mean() < 0.002, "only rays grazing the box's faces may differ (float32 entry/exit)"
    return ref


def test_the_march_with_types_by_region_matches_its_float64_reference(gpu, ctx, rng):
    """A random map of types over the volume (and past it: its edge texels hold beyond), with no single
    type: the march against the reference reading the map's float64 twin."""
    d = random_volume(rng)
    app = scene(gpu, d, DAY, empty_space_skipping=False, min_transmittance=0.0, steps=128, step_growth=0.002)
    march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation.sets()
    layout = sim.layout()
    lo, extent = np.asarray(layout.lo), np.asarray(layout.hi) - np.asarray(layout.lo)
    types = rng.uniform(0.0, 1.0, (4, 5))
    types[0, 0], types[-1, -1] = 0.0, 1.0                                   # the ends of the range
    march.configure(cloud_type=None, type_map=CloudTypeMap(types, origin=(lo[0] + 60.0, lo[2] - 40.0),
                                                           size=(0.7 * extent[0], extent[2] + 80.0)))
    # as one type's march (the half-float columns), and the texture unit's bilinear weights (8 bits of
    # sub-texel position on common hardware: the type off by up to 1/256 of a neighbour's difference)
    ref = march_against_reference(gpu, app, d, colour=0.004, coverage=0.003)
    one = march_reference(d, shading_volume(sim), sim.settings, march.settings.replace(type_map=None, cloud_type=0.5),
                          layout, app.resource(Camera), DAY, gpu.size, field=read_field(sim.a[DIFFUSION]),
                          ground_sun=ground_sun_of(sim))
    assert np.abs(one["alpha"] - ref["alpha"]).max() > 0.1, "the map must shape the clouds otherwise than one type"
    app.close()


def test_a_one_texel_map_is_its_type_everywhere(gpu, ctx, rng):
    """The smallest map (one texel, held everywhere) draws exactly what the one type draws: the texture's
    float32 value is the uniform's."""
    d = random_volume(rng)
    kind = float(np.float32(rng.uniform(0.55, 1.0)))              # towers, exactly representable
    app = scene(gpu, d, DAY, min_transmittance=0.0, cloud_type=kind)
    aim(app, (80.0, 520.0, -220.0), target=(160.0, 470.0, 200.0))
    one = linear(app)
    march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    march.configure(cloud_type=None, type_map=CloudTypeMap(np.array([[kind]]), origin=(-1e5, -1e5), size=(1.0, 1.0)))
    mapped = linear(app)
    assert (one[..., 3] > 0.05).mean() > 0.02
    np.testing.assert_array_equal(mapped, one)
    app.close()


def test_a_type_map_reads_bilinearly_and_holds_its_edges():
    m = CloudTypeMap(np.array([[0.0, 1.0], [0.5, 0.5]]), origin=(100.0, -50.0), size=(40.0, 20.0))
    # texel centres at x 110, 130 and z -45, -35
    assert m.at(110.0, -45.0) == 0.0 and m.at(130.0, -45.0) == 1.0 and m.at(120.0, -45.0) == 0.5
    assert m.at(120.0, -40.0) == pytest.approx(0.5)
    np.testing.assert_array_equal(m.at(np.array([-1e6, 1e6]), np.array([-45.0, -45.0])), [0.0, 1.0])   # the edges hold
    assert m.types.dtype == np.float32 and not m.types.flags.writeable
    assert m.at(np.zeros((3, 2)), np.zeros((3, 2))).shape == (3, 2)


@pytest.mark.parametrize("types, fields, message", [
    (np.full((2, 2), 1.5), {}, "in \\[0, 1\\]"),
    (np.array([[0.2, np.nan]]), {}, "NaN"),
    (np.zeros(4), {}, "2D array"),
    (np.zeros((2, 0)), {}, "2D array"),
    (np.array([["a"]]), {}, "numbers"),
    (np.zeros((2, 2)), {"size": (0.0, 10.0)}, "CloudTypeMap.size"),
    (np.zeros((2, 2)), {"origin": (float("inf"), 0.0)}, "CloudTypeMap.origin"),
])
def test_a_bad_type_map_is_refused_naming_what_is_wrong(types, fields, message):
    with pytest.raises(ValueError, match=message):
        CloudTypeMap(types, **fields)


def test_the_type_map_setting_takes_a_map_or_none():
    m = CloudTypeMap(np.zeros((2, 2)))
    assert RaymarchCloudSettings(type_map=m).type_map is m and RaymarchCloudSettings().type_map is None
    with pytest.raises(ValueError, match="type_map must be a CloudTypeMap"):
        RaymarchCloudSettings(type_map=np.zeros((2, 2)))


def test_towers_take_the_sun_of_their_own_heights(gpu, ctx, rng):
    """A sun whose colour changes with altitude: congestus towers above the layer take the colour of their
    own heights (the light's sun colours span the towers), in the march and its reference alike."""
    d = random_volume(rng)
    app = scene(gpu, d, BY_ALTITUDE, empty_space_skipping=False, min_transmittance=0.0, steps=128,
                step_growth=0.002, cloud_type=CLOUD_TYPES["congestus"])
    march_against_reference(gpu, app, d, colour=0.003, coverage=0.002, sun=BY_ALTITUDE)
    app.close()
    sources, _, _ = layer_sun(BY_ALTITUDE, (400.0, 520.0), 1 + TOWER)
    assert sun_source_at(sources, 1 + TOWER, 1 + TOWER)[0] == pytest.approx((400.0 + (1 + TOWER) * 120.0) / 500.0)


def test_congestus_towers_above_the_simulated_layer(gpu, ctx):
    """A layer full of cloud seen edge-on from above its top: congestus rises into the upper half of the
    view, cumulus stays below the horizon line of its top."""
    d = np.full((16, 6, 16), 0.8, np.float32)
    app = scene(gpu, d, DAY, min_transmittance=0.0, cloud_type=CLOUD_TYPES["congestus"])
    sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation.sets()
    layout = sim.layout()
    top = float(layout.hi[1])
    aim(app, (160.0, top + 20.0, -400.0), target=(160.0, top + 20.0, 160.0))
    tower = linear(app)[..., 3]
    march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    march.configure(cloud_type=CLOUD_TYPES["cumulus"])
    flat = linear(app)[..., 3]
    h = tower.shape[0]
    upper = slice(h // 2 + 2, None)                               # rows looking up, above the camera's height
    assert (tower[upper] > 0.5).mean() > 0.2 and (flat[upper] > 0.01).mean() == 0.0
    app.close()


def test_with_a_type_skipping_keeps_the_columns_whole(gpu, ctx, rng):
    d = np.zeros((16, 8, 16), np.float32)
    d[4:12, 0:2, 4:12] = 1.0                 # density in the lowest band only: congestus lifts it to the top
    app = scene(gpu, d, DAY, empty_space_skipping=False, min_transmittance=0.0, cloud_type=1.0)
    plugin = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    aim(app, (160.0, 900.0, -400.0), target=(160.0, 600.0, 200.0))
    full = linear(app)
    plugin.configure(empty_space_skipping=True)
    skipped = linear(app)
    scale = full[..., :3].max()
    assert scale > 0.1 and (full[..., 3] > 0.5).mean() > 0.02
    assert np.abs(skipped - full).max() < 0.02 * scale, "skipping cut the type's columns"
    app.close()


@pytest.mark.parametrize("value", [-0.1, 1.5, float("nan"), "cumulus", True])
def test_a_bad_cloud_type_is_refused_naming_the_field(value):
    with pytest.raises(ValueError, match="cloud_type"):
        RaymarchCloudSettings(cloud_type=value)


def test_the_default_is_cumulus_and_none_is_the_simulations_own_shape():
    assert RaymarchCloudSettings().cloud_type == CLOUD_TYPES["cumulus"]
    assert RaymarchCloudSettings(cloud_type=None).cloud_type is None


def test_the_weather_demos_type_follows_the_weather():
    from atmos.demos.weather import cloud_type_at
    assert [cloud_type_at(p) for p in (0.0, 0.5, 1.0)] == [CLOUD_TYPES[k] for k in ("cumulus", "congestus", "stratus")]
    phases = np.linspace(0.0, 1.0, 101)
    kinds = np.array([cloud_type_at(p) for p in phases])
    assert np.all((kinds >= 0.0) & (kinds <= 1.0)) and np.all(np.abs(np.diff(kinds)) <= 0.021), "smooth in phase"


def test_the_weather_demos_regions_spread_around_the_weathers_type():
    from atmos.demos._cloudscape import region_offsets, regional_types
    from atmos.demos.weather import REGION_SPREAD
    offsets = region_offsets(0)
    assert np.abs(offsets).max() == pytest.approx(1.0) and offsets.std() > 0.2
    np.testing.assert_array_equal(offsets, region_offsets(0))                       # replayable
    m = regional_types(CLOUD_TYPES["cumulus"], offsets, REGION_SPREAD)
    assert m.types.min() < 0.5 - 0.5 * REGION_SPREAD and m.types.max() > 0.5 + 0.5 * REGION_SPREAD
    stratus = regional_types(0.0, offsets, REGION_SPREAD)
    assert stratus.types.min() == 0.0 and stratus.types.max() <= REGION_SPREAD + 1e-6


def test_typed_columns_hold_the_shape_drawn():
    """typed_column (column.glsl's twin): the simulated column where no type is drawn; a thin stratus sheet
    holds less than the simulated column, a towering congestus more; its midpoint sum is the profile's
    integral within the rule's error (checked against 4,000 points): at most a step's worth of the column's
    largest density c at each of the two edges of where it holds cloud."""
    from atmos.plugins.clouds.volume.shape import TYPED_STEPS, typed_column
    ny = 8
    sums = np.array([0.0, 0.2, 1.0, 2.8, 8.0])
    assert np.array_equal(typed_column(sums, 0.0, 0.0, ny), sums)
    full = [typed_column(2.8, 0.0, 0.0, ny, CLOUD_TYPES[k]) for k in ("stratus", "cumulus", "congestus")]
    assert full[0] < 2.8 < full[2] and full[0] < full[1] < full[2], full
    for t in (0.0, 0.3, 0.5, 0.8, 1.0):
        top = max(march_top(t), 1.0)
        h = (np.arange(4000) + 0.5) / 4000 * top
        fine = np.array([ny * type_density(s / ny, h, t).sum() * top / 4000 for s in sums])
        c = np.minimum(sums / ny / COLUMN_FULL, 1.0)
        assert np.all(np.abs(typed_column(sums, 0.0, 0.0, ny, t) - fine) <= 2 * ny * top / TYPED_STEPS * c + 1e-12)
    types = CloudTypeMap(np.array([[0.0, 1.0]]), (0.0, 0.0), (200.0, 100.0))
    x = np.array([0.0, 200.0])                      # the map's two edge texels: stratus, congestus
    np.testing.assert_allclose(typed_column(np.full(2, 2.8), x, np.zeros(2), ny, type_map=types), full[::2])


def test_the_march_publishes_the_type_its_columns_shadow_with(gpu, ctx):
    """A scene marching its clouds with a type has every column reader (ground shadows, shadow map,
    shafts, the light from below) shape the columns like it (DrawnShape); off, untyped, or drawn by the
    sprites: the simulation's own columns."""
    from atmos import App, DefaultPlugins
    from atmos.plugins.clouds.sprites import CloudRenderPlugin
    from atmos.plugins.clouds.volume.shape import DrawnShape
    density = np.zeros((8, 4, 8), np.float32)
    density[2:6, :2, 2:6] = 1.0
    march = RaymarchCloudsPlugin(cloud_type=1.0)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(density=density), march)
    try:
        shape = app.resource(DrawnShape)
        assert shape.current() == (1.0, None, None)
        types = CloudTypeMap(np.array([[0.0, 1.0]]))
        march.configure(type_map=types)
        cloud_type, type_map, texture = shape.current()
        assert type_map is types and texture is not None and texture.size == (2, 1)
        march.configure(cloud_type=None, type_map=None)
        assert shape.current() is None
        march.configure(cloud_type=0.5, enabled=False)
        assert shape.current() is None
    finally:
        app.close()
    assert shape.source is None, "the march takes its source out when it goes"
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(density=density), CloudRenderPlugin())
    try:
        assert app.resource(DrawnShape).current() is None
    finally:
        app.close()


def test_the_typed_columns_table_holds_the_midpoint_sum_within_its_interpolation(rng):
    """column.glsl reads a typed column from a table (shape.py column_table: nodes in the coverage's square
    root and in the type) in place of TYPED_STEPS profile samples: interpolated on fresh random columns and
    types it is within 0.4 % of the type's full column of the midpoint sum it was built from (column_mean),
    exact at the nodes, flat past a full column, and 0 for an empty one."""
    from atmos.plugins.clouds.volume.shape import COLUMN_NODES, column_lookup, column_mean, column_table
    m = COLUMN_FULL * rng.uniform(0.0, 1.0, 20000) ** 2
    t = np.where(rng.uniform(size=m.size) < 0.25, 0.5, rng.uniform(0.0, 1.0, m.size))
    err = np.abs(column_lookup(m, t) - column_mean(m, t)) / column_mean(COLUMN_FULL, t)
    assert err.max() <= 0.004, f"table error {err.max():.4f} of a full column"
    nu, nt = COLUMN_NODES
    s, tt = np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 1, nt))
    np.testing.assert_allclose(column_lookup(s * s * COLUMN_FULL, tt), column_mean(s * s * COLUMN_FULL, tt),
                               rtol=2.0 ** -23, atol=1e-12)
    assert column_table().shape == (nt, nu) and column_table().dtype == np.float32
    np.testing.assert_array_equal(column_lookup(np.array([COLUMN_FULL, 5.0]), 0.7), column_lookup(COLUMN_FULL, 0.7))
    assert np.all(column_lookup(0.0, np.linspace(0, 1, 9)) == 0.0)
