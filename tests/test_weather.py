"""Weather ellipsoids (thesis sec. 4.3.3.4-4.3.3.5) and the region volume on the GPU."""
import dataclasses
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.world import World
from atmos.plugins.clouds.weather import (MAX_CLOUD_DENSITY, Ellipsoid, RegionVolume, VolumeOrigin, WeatherSettings,
                                   WeatherPlugin, ellipsoid_array, probabilities, region_volume,
                                   step_weather, wind_field_at)

# max abs error of the GPU region volume against the float64 reference, values in [0, 1]
TOLERANCE = {"f4": 2e-6, "f2": 1e-3}   # r16f: 11-bit mantissa, half an ulp below 1 is 2.4e-4


@pytest.fixture
def world():
    w = World()
    yield w
    w.close()


def params(**kw):
    base = dict(cloud_density=40, density_adaption=2, cloud_size=3.0, cloud_size_variance=1.0,
                lifetime=1e6, lifetime_variance=0.0, shrink_time=0.0, region_margin=16.0,
                volume_shape=(32, 8, 32), wind=(0.0, 0.0, 0.0), wind_variance=0.0)
    base.update(kw)
    return WeatherSettings(**base)


def ellipsoids(world):
    return sorted(world.get_component(Ellipsoid), key=lambda pair: pair[0])


def random_ellipsoids(rng, n, shape, spill=4.0, rmax=6.0):
    a = np.zeros((n, 8), np.float32)
    a[:, 0:3] = rng.uniform(-spill, np.array(shape) + spill, (n, 3))
    a[:, 3] = rng.uniform(-math.pi, 3 * math.pi, n)
    a[:, 4:7] = rng.uniform(0.2, rmax, (n, 3))
    return a


def dense_reference(a, shape):
    """A second, vectorized float64 reference (independent of reference.region_volume's loop)."""
    a = np.asarray(a, np.float64)
    a = a[(a[:, 4:7] > 0).all(axis=1)]
    grid = np.stack(np.meshgrid(*(np.arange(n) + 0.5 for n in shape), indexing="ij"), -1).reshape(-1, 3)
    out = np.zeros(len(grid))
    for chunk in np.array_split(a, max(1, len(a) // 2000)):
        if not len(chunk):
            continue
        d = grid[None, :, :] - chunk[:, None, 0:3]
        cs, sn = np.cos(chunk[:, 3])[:, None], np.sin(chunk[:, 3])[:, None]
        lx = (cs * d[..., 0] + sn * d[..., 2]) / chunk[:, 4:5]
        ly = d[..., 1] / chunk[:, 5:6]
        lz = (-sn * d[..., 0] + cs * d[..., 2]) / chunk[:, 6:7]
        out = np.maximum(out, (1 - np.sqrt(lx * lx + ly * ly + lz * lz)).max(axis=0))
    return out.reshape(shape)


def render_checked(gpu, a, shape, dtype="f4"):
    """Render ``a`` with every cell pre-filled with NaN; assert every cell was written."""
    rv = RegionVolume(gpu, shape, dtype=dtype)
    try:
        nx, ny, nz = shape
        fill = np.full((nz, ny, nx), np.nan, np.float32 if dtype == "f4" else np.float16)
        rv.texture.write(fill.tobytes())
        assert np.isnan(rv.download()).all()
        rv.render(a)
        got = rv.download()
    finally:
        rv.release()
    assert got.shape == tuple(shape) and got.dtype == np.float32
    assert not np.isnan(got).any(), "some cells were not written"
    return got


# -- rules 1 and 2: density ---------------------------------------------------------------------
def test_count_converges_at_adaption_pace(world, rng):
    p = params(cloud_density=40, density_adaption=2)
    counts = [step_weather(world, p, rng).count for _ in range(25)]
    assert counts == [2 * i for i in range(1, 21)] + [40] * 5   # never faster than 2 per step
    p = p.replace(cloud_density=31)
    counts = [step_weather(world, p, rng).count for _ in range(6)]
    assert counts == [38, 36, 34, 32, 31, 31]
    p = p.replace(cloud_density=100, density_adaption=1000)
    report = step_weather(world, p, rng)
    assert report.created == 69 and report.count == 100


def test_removal_prefers_ellipsoids_out_of_view(world, rng):
    p = params(cloud_density=0, density_adaption=3)
    inside = [world.create_entity(Ellipsoid(x=16, y=4, z=16, lifetime=1e6)) for _ in range(4)]
    far = world.create_entity(Ellipsoid(x=-12, y=4, z=16, lifetime=1e6))
    near = world.create_entity(Ellipsoid(x=40, y=4, z=16, lifetime=1e6))
    old = world.create_entity(Ellipsoid(x=16, y=4, z=16, age=9e5, lifetime=1e6))
    report = step_weather(world, p, rng)
    left = {e for e, _ in ellipsoids(world)}
    assert report.removed == 3 and left == set(inside)
    assert far not in left and near not in left and old not in left


def test_density_zero_means_no_clouds(gpu, world, rng, ctx):
    p = params(cloud_density=0)
    for _ in range(5):
        assert step_weather(world, p, rng).count == 0
    a = ellipsoid_array(world)
    assert a.shape == (0, 8)
    got = render_checked(gpu, a, (8, 4, 6))
    assert (got == 0).all()
    p_hum, p_act, p_ext = probabilities(got, p)
    assert (p_hum == 0).all() and (p_act == 0).all() and (p_ext == 1).all()


def test_maximal_density(gpu, world, rng, ctx):
    p = params(cloud_density=MAX_CLOUD_DENSITY, density_adaption=MAX_CLOUD_DENSITY,
               volume_shape=(6, 3, 5), region_margin=2.0, cloud_size=1.5, cloud_size_variance=1.0)
    assert step_weather(world, p, rng).count == MAX_CLOUD_DENSITY
    a = ellipsoid_array(world)
    got = render_checked(gpu, a, p.volume_shape)
    want = dense_reference(a, p.volume_shape)
    assert np.abs(got - np.maximum(want, 0)).max() < TOLERANCE["f4"]
    assert (got > 0.3).all()    # 100,000 ellipsoids in a 10×7×9 region cover every cell
    with pytest.raises(ValueError, match="cloud_density"):
        params(cloud_density=MAX_CLOUD_DENSITY + 1)


# -- rule 3 and the shrink ----------------------------------------------------------------------
def test_ellipsoids_shrink_then_die_at_their_lifetime(world, rng):
    p = params(cloud_density=5, density_adaption=5, lifetime=10.0, lifetime_variance=0.0, shrink_time=4.0)
    step_weather(world, p, rng)
    first = {e for e, _ in ellipsoids(world)}
    scales = []
    for step in range(1, 10):
        step_weather(world, p, rng)
        pairs = ellipsoids(world)
        assert {e for e, _ in pairs} == first, f"died early at age {step}"
        scales.append({round(c.scale, 6) for _, c in pairs})
    assert scales == [{1.0}] * 6 + [{0.75}, {0.5}, {0.25}]
    a = ellipsoid_array(world)
    radii = np.array([(c.rx, c.ry, c.rz) for _, c in ellipsoids(world)])
    assert np.allclose(a[:, 4:7], 0.25 * radii, rtol=1e-6)      # the region sees the shrunk radii
    report = step_weather(world, p, rng)                       # age 10 == lifetime: gone, replaced
    assert report.died == 5 and report.created == 5
    assert not first & {e for e, _ in ellipsoids(world)}


def test_lifetimes_and_sizes_follow_their_variance(world, rng):
    p = params(cloud_density=2000, density_adaption=2000, lifetime=50.0, lifetime_variance=20.0,
               cloud_size=5.0, cloud_size_variance=2.0, vertical_scale=0.4)
    step_weather(world, p, rng)
    cs = [c for _, c in ellipsoids(world)]
    life = np.array([c.lifetime for c in cs])
    rx = np.array([c.rx for c in cs])
    assert 30 <= life.min() and life.max() <= 70 and life.std() > 5
    assert 3 <= rx.min() and rx.max() <= 7
    assert np.allclose([c.ry for c in cs], [0.4 * (c.rx + c.rz) / 2 for c in cs])
    lo, hi = p.region_bounds()
    xyz = np.array([(c.x, c.y, c.z) for c in cs])
    assert (xyz >= lo).all() and (xyz <= hi).all()


# -- rule 4: wind -------------------------------------------------------------------------------
def test_wind_moves_ellipsoids_with_a_small_variance(world, rng):
    p = params(cloud_density=50, density_adaption=50, wind=(2.0, 0.0, -1.0), wind_variance=0.05,
               region_margin=1000.0)
    step_weather(world, p, rng)
    before = {e: (c.x, c.y, c.z) for e, c in ellipsoids(world)}
    for _ in range(10):
        step_weather(world, p, rng, dt=0.5)
    after = {e: (c.x, c.y, c.z) for e, c in ellipsoids(world)}
    both = before.keys() & after.keys()      # (a few born at the region's edge may blow out of it)
    assert len(both) >= 40
    move = np.array([np.subtract(after[e], before[e]) for e in both]) / 5.0   # cells per second
    assert np.abs(move[:, 0] - 2.0).max() <= 0.05 + 1e-9
    assert np.abs(move[:, 2] + 1.0).max() <= 0.05 + 1e-9
    assert np.abs(move[:, 1]).max() == 0.0
    assert move[:, 0].std() > 0.005        # not every ellipsoid moves with the same speed


def test_wind_field_is_interpolated_bilinearly(world, rng):
    field = rng.normal(size=(8, 8, 2))
    lo, hi = (-16.0, -16.0), (48.0, 48.0)          # 64 cells: grid cells of 8, centres at -12, -4, ...
    centres = -12.0 + 8.0 * np.arange(8)
    x, z = np.meshgrid(centres, centres, indexing="ij")
    assert np.allclose(wind_field_at(field, lo, hi, x.ravel(), z.ravel()), field.reshape(-1, 2))
    # halfway between centres: the mean of the two; outside the centres: clamped to the edge
    mid = wind_field_at(field, lo, hi, [-8.0, -12.0, -16.0, 48.0], [-12.0, -8.0, -16.0, 48.0])
    assert np.allclose(mid, [(field[0, 0] + field[1, 0]) / 2, (field[0, 0] + field[0, 1]) / 2,
                             field[0, 0], field[7, 7]])
    # a linear field is reproduced exactly anywhere between the centres, through the rules too
    linear = np.stack(np.meshgrid(np.arange(8.0), 2 * np.arange(8.0), indexing="ij"), -1)
    p = params(cloud_density=1, density_adaption=1, wind=(0.5, 0.0, 0.0), wind_field=linear)
    e = Ellipsoid(x=3.0, y=4.0, z=25.0, lifetime=1e6)
    world.create_entity(e)
    step_weather(world, p, rng, dt=0.1)
    u, v = (3.0 + 16) / 8 - 0.5, (25.0 + 16) / 8 - 0.5
    assert e.vx == pytest.approx(0.5 + u) and e.vz == pytest.approx(2 * v)
    assert e.x == pytest.approx(3.0 + 0.1 * (0.5 + u)) and e.z == pytest.approx(25.0 + 0.1 * 2 * v)


# -- rule 5: region boundings -------------------------------------------------------------------
def test_ellipsoid_leaving_the_region_is_removed_and_replaced(world, rng):
    p = params(cloud_density=1, density_adaption=1, wind=(3.0, 0.0, 0.0), region_margin=8.0)
    lost = world.create_entity(Ellipsoid(x=32 + 8 - 1.0, y=4, z=10, lifetime=1e6))  # 1 cell from the edge
    report = step_weather(world, p, rng)
    assert report.left == 1 and report.created == 1
    (entity, e), = ellipsoids(world)
    assert entity != lost
    lo, hi = p.region_bounds()
    assert lo[0] <= e.x <= hi[0] and lo[2] <= e.z <= hi[2]
    # ellipsoids out of view but inside the boundings are kept
    kept = world.create_entity(Ellipsoid(x=-6.0, y=4, z=-7.0, lifetime=1e6))
    p = p.replace(wind=(0.0, 0.0, 0.0), cloud_density=2)
    step_weather(world, p, rng)
    assert kept in {e for e, _ in ellipsoids(world)}


def _holding_pattern(world, rng, margin, steps=36, radius=24.0):
    """Fly the volume (32×8×32 cells) once round a circle in ``steps`` steps; return what was
    in view at the start, and per step the set of alive entities and their positions."""
    p = params(cloud_density=400, density_adaption=400, region_margin=margin, volume_shape=(32, 8, 32))
    def origin(step):
        t = 2 * math.pi * step / steps
        return (radius * (math.cos(t) - 1), 0.0, radius * math.sin(t))
    step_weather(world, p, rng, origin=origin(0))
    start = {e: (c.x, c.y, c.z) for e, c in ellipsoids(world)}
    in_view = {e for e, (x, y, z) in start.items() if 0 <= x < 32 and 0 <= z < 32}
    history = []
    for step in range(1, steps + 1):
        step_weather(world, p, rng, origin=origin(step))
        history.append({e: (c.x, c.y, c.z) for e, c in ellipsoids(world)})
    return start, in_view, history, p


def test_fast_viewer_comes_back_to_clouds_inside_the_boundings(world, rng):
    # ~4.2 cells per step round a circle of radius 24 with a 32-cell view: the view leaves
    # most of its clouds behind and then turns back to them
    start, in_view, history, p = _holding_pattern(world, rng, margin=48.0)
    assert len(in_view) >= 5
    half = history[len(history) // 2 - 1]     # the view is 48 cells to the -x side
    out_of_view = {e for e in in_view if e in half and not (-48 <= half[e][0] < -16)}
    assert len(out_of_view) >= 3, "the volume should have flown away from its first clouds"
    end = history[-1]                         # back where it started: the same clouds in view
    assert in_view == {e for e, (x, y, z) in end.items() if 0 <= x < 32 and 0 <= z < 32 and e in start}
    for snapshot in history:                 # never removed, never moved (no wind)
        assert in_view <= snapshot.keys()
        assert all(snapshot[e] == start[e] for e in in_view)
    assert all(len(s) == 400 for s in history)


def test_without_a_margin_a_fast_viewer_loses_its_clouds(world, rng):
    start, in_view, history, p = _holding_pattern(world, rng, margin=0.0)
    assert in_view and not in_view & history[-1].keys()
    assert len(history[-1]) == 400           # replaced by new ellipsoids around the current view


def test_rules_are_deterministic_for_a_seed():
    arrays = []
    for _ in range(2):
        w = World()
        gen = np.random.default_rng(1234)
        p = params(cloud_density=30, density_adaption=4, lifetime=8.0, lifetime_variance=3.0,
                   shrink_time=2.0, wind=(1.0, 0.0, 0.5), wind_variance=0.2, region_margin=4.0)
        for step in range(40):
            step_weather(w, p, gen, dt=0.5, origin=(step * 0.3, 0.0, 0.0))
        arrays.append(ellipsoid_array(w, origin=(12.0, 0.0, 0.0)))
        w.close()
    assert len(arrays[0]) >= 20 and np.array_equal(arrays[0], arrays[1])


def test_one_cell_volume(gpu, world, rng, ctx):
    p = params(cloud_density=7, density_adaption=7, volume_shape=(1, 1, 1), region_margin=0.0,
               cloud_size=0.8, cloud_size_variance=0.1)
    assert step_weather(world, p, rng).count == 7
    lo, hi = p.region_bounds()
    assert all(lo[0] <= c.x <= hi[0] and lo[2] <= c.z <= hi[2] for _, c in ellipsoids(world))
    a = ellipsoid_array(world)
    got = render_checked(gpu, a, (1, 1, 1))
    assert abs(got[0, 0, 0] - region_volume(a, (1, 1, 1))[0, 0, 0]) < TOLERANCE["f4"]
    one = np.array([[0.5, 0.5, 0.5, 0.3, 1, 1, 1, 0], [0.5, 0.5, 1.0, 0, 1, 1, 1, 0]], np.float32)
    assert render_checked(gpu, one[:1], (1, 1, 1))[0, 0, 0] == pytest.approx(1.0)
    assert render_checked(gpu, one[1:], (1, 1, 1))[0, 0, 0] == pytest.approx(0.5)


# -- parameters ----------------------------------------------------------------------------------
@pytest.mark.parametrize("field, value", [
    ("cloud_density", -1), ("cloud_density", 2.5), ("density_adaption", 0),
    ("cloud_size", 0.0), ("cloud_size", -3.0), ("cloud_size", float("nan")),
    ("cloud_size_variance", 7.0), ("cloud_size_variance", -0.1),
    ("lifetime", float("inf")), ("lifetime", 0.0), ("lifetime_variance", 70.0),
    ("shrink_time", -1.0), ("region_margin", -2.0), ("vertical_scale", 0.0), ("altitude", 1.5),
    ("volume_shape", (0, 4, 4)), ("volume_shape", (4, 4)), ("volume_shape", (4.5, 4, 4)),
    ("wind", (1.0, float("nan"), 0.0)), ("wind", (1.0, 0.0)), ("wind_variance", -0.1),
    ("wind_field", np.zeros((8, 8))), ("wind_field", np.full((8, 8, 2), np.inf)),
    ("hum_scale", 1.5), ("ext_scale", -0.1), ("vanish_threshold", float("nan")),
])
def test_bad_settings_name_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        WeatherSettings(**{field: value})


def test_settings_are_frozen_and_changed_by_a_checked_replace(world, rng):
    p = params()
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.cloud_size_variance = 10.0
    with pytest.raises(ValueError, match="WeatherSettings.cloud_size_variance must be >= 0 and < cloud_size"):
        p.replace(cloud_size_variance=10.0)
    with pytest.raises(ValueError, match="dt"):
        step_weather(world, params(), rng, dt=float("nan"))


# -- region volume on the GPU ---------------------------------------------------------------------
@pytest.mark.parametrize("dtype", ["f4", "f2"])
@pytest.mark.parametrize("shape", [(16, 8, 16), (13, 7, 5), (1, 9, 2)])
def test_region_volume_matches_reference(gpu, ctx, rng, shape, dtype):
    a = random_ellipsoids(rng, int(rng.integers(1, 60)), shape)
    a[::7, 4 + int(rng.integers(0, 3))] = 0.0          # fully shrunk: contributes nothing
    got = render_checked(gpu, a, shape, dtype)
    want = region_volume(a, shape)
    assert np.abs(got - want).max() <= TOLERANCE[dtype]
    dense = dense_reference(a, shape)                   # unclipped: < 0 outside every ellipsoid
    assert np.allclose(want, np.maximum(dense, 0), atol=1e-12)
    assert (got[dense < -1e-4] == 0).all()              # outside every ellipsoid: exactly 0
    assert got.min() >= 0 and got.max() <= 1


def test_region_volume_falloff_is_linear(gpu, ctx):
    shape = (21, 11, 21)
    a = np.array([[10.5, 5.5, 10.5, 0.0, 8.0, 4.0, 6.0, 0.0]], np.float32)
    got = render_checked(gpu, a, shape)
    assert got[10, 5, 10] == pytest.approx(1.0)
    assert got[14, 5, 10] == pytest.approx(0.5, abs=1e-6)        # 4 of 8 cells along x
    assert got[10, 7, 10] == pytest.approx(0.5, abs=1e-6)        # 2 of 4 along y
    assert got[10, 5, 13] == pytest.approx(0.5, abs=1e-6)        # 3 of 6 along z
    assert got[18, 5, 10] == 0 and got[10, 10, 10] == 0 and got[0, 0, 0] == 0
    # yaw: a quarter turn swaps the x and z radii
    a[0, 3] = math.pi / 2
    turned = render_checked(gpu, a, shape)
    assert turned[10, 5, 16] == pytest.approx(1 - 6 / 8, abs=1e-5)
    assert turned[16, 5, 10] == pytest.approx(0.0, abs=1e-5)


def test_region_volume_zero_and_ten_thousand_ellipsoids(gpu, ctx, rng, world):
    shape = (12, 6, 10)
    assert (render_checked(gpu, np.zeros((0, 8), np.float32), shape) == 0).all()
    p = params(cloud_density=10_000, density_adaption=10_000, volume_shape=shape, region_margin=6.0,
               cloud_size=2.0, cloud_size_variance=1.5)
    assert step_weather(world, p, rng).count == 10_000
    a = ellipsoid_array(world)
    got = render_checked(gpu, a, shape)
    assert np.abs(got - region_volume(a, shape)).max() <= TOLERANCE["f4"]
    # ellipsoids far outside the volume render nothing, at no cost
    far = a.copy()
    far[:, 0] += 1000
    rv = RegionVolume(gpu, shape)
    rv.render(far)
    assert rv.work_items == 0 and (rv.download() == 0).all()
    rv.release()


def test_region_volume_re_renders_and_rejects_bad_input(ctx, gpu, rng):
    shape = (9, 5, 7)
    rv = RegionVolume(gpu, shape)
    for _ in range(3):
        a = random_ellipsoids(rng, 20, shape)
        rv.render(a)
        assert np.abs(rv.download() - region_volume(a, shape)).max() <= TOLERANCE["f4"]
    with pytest.raises(ValueError, match="ellipsoids"):
        rv.render(np.zeros((3, 7)))
    with pytest.raises(ValueError, match="ellipsoids"):
        rv.render(np.full((1, 8), np.nan))
    rv.release()
    with pytest.raises(RuntimeError):
        rv.render(np.zeros((0, 8)))
    with pytest.raises(ValueError, match="shape"):
        RegionVolume(gpu, (4, 0, 4))
    with pytest.raises(ValueError, match="dtype"):
        RegionVolume(gpu, (4, 4, 4), dtype="f8")


@pytest.mark.parametrize("dtype", ["f4", "f2"])
def test_probabilities_gpu_and_reference(gpu, ctx, rng, dtype):
    shape = (11, 6, 9)
    p = WeatherSettings(hum_scale=0.2, act_scale=0.01, ext_scale=0.3, vanish_threshold=0.05)
    rv = RegionVolume(gpu, shape, dtype=dtype)
    rv.render(random_ellipsoids(rng, 12, shape))
    region = rv.download()
    rv.probabilities(p)
    got = rv.download_probabilities()
    want = probabilities(region, p)
    tol = 1e-6 if dtype == "f4" else 1e-3
    for g, w in zip(got, want):
        assert g.shape == shape and np.abs(g - w).max() <= tol
    p_hum, p_act, p_ext = want
    r = region.astype(np.float64)
    assert np.allclose(p_hum, 0.2 * r) and np.allclose(p_act, 0.01 * r)
    assert np.allclose(p_ext[r > 0.05], 0.3 * (1 - r[r > 0.05]))
    assert (p_ext[r <= 0.05] == 1).all() and (r <= 0.05).any() and (r > 0.05).any()
    rv.release()


# -- the App plugin --------------------------------------------------------------------------------
def test_weather_plugin_in_an_app(gpu, ctx):
    p = params(cloud_density=20, density_adaption=5, volume_shape=(16, 8, 16), region_margin=4.0,
               wind=(3.0, 0.0, 0.0))
    app = App(gpu, fixed_step=1 / 30)
    plugin = WeatherPlugin(p, seed=7)
    app.add_plugins(plugin)
    app.run_frames(6, dt=1 / 30)
    labels = {s.label: s.stage for s in app.schedule.systems}
    assert labels["weather"] == "simulate" and labels["weather_region"] == "simulate"
    assert plugin.last_report.count == 20
    app.resource(VolumeOrigin).x = 5.0
    app.run_frames(1, dt=1 / 30)
    region = app.resource(RegionVolume)
    a = ellipsoid_array(app.world, origin=(5.0, 0.0, 0.0))
    assert np.abs(region.download() - region_volume(a, (16, 8, 16))).max() <= TOLERANCE["f4"]
    assert region.download().max() > 0
    app.close()
    assert plugin.region is None


def test_weather_plugin_without_gpu():
    app = App()
    app.add_plugins(WeatherPlugin(params(cloud_density=10, density_adaption=10), seed=1))
    app.run_frames(3, dt=1 / 30)
    assert len(app.world.get_component(Ellipsoid)) == 10
    assert app.get_resource(RegionVolume) is None
    app.close()
