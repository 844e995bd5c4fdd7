"""The cloud chain: weather → region → automaton → smoothing → density maps, sliced over frames."""
import numpy as np
import pytest

from atmos.app import App
from atmos.plugins.clouds import CloudSettings, CloudsPlugin, read_volume, reference
from atmos.plugins.clouds.weather import Ellipsoid, VolumeOrigin, WeatherSettings


def params(shape=(32, 8, 32), **kw):
    base = dict(volume_shape=shape, cloud_density=24, density_adaption=2, cloud_size=4.0, cloud_size_variance=1.5,
                region_margin=6.0, lifetime=40.0, lifetime_variance=10.0, hum_scale=0.2, act_scale=0.01,
                ext_scale=0.1, altitude=0.5, altitude_variance=0.1, vertical_scale=0.5, wind=(0.5, 0.0, 0.25))
    base.update(kw)
    return WeatherSettings(**base)


def clouds_app(gpu, p, settings=None, seed=3, **kw):
    app = App(gpu)
    plugin = CloudsPlugin(settings or CloudSettings(smoothing_slices=2, group_size=(8, 8)), weather=p, seed=seed, **kw)
    app.add_plugins(plugin)
    app.startup()
    return app, plugin.simulation


def test_sliced_frames_equal_whole_steps_and_readers_never_see_c(gpu, ctx):
    naive_app, naive = clouds_app(gpu, params())
    sliced_app, sliced = clouds_app(gpu, params())
    for _ in range(6):
        naive.job.run_step()
    c_seen = []
    while sliced.job.step < naive.job.step:
        sliced_app.update(1 / 30)              # one slice per frame (the default budget)
        a, b, t = sliced.view()
        c_seen.append(sliced.triple.c is a or sliced.triple.c is b)
        assert 0.0 <= t < 1.0
    assert not any(c_seen)
    for x, y in zip(naive.view()[:2], sliced.view()[:2]):
        assert np.array_equal(read_volume(x["density"]), read_volume(y["density"]))
    naive_app.close()
    sliced_app.close()


def test_warm_up_gives_the_sets_of_whole_steps(gpu, ctx):
    """The warm-up's early steps run the weather and automaton alone: A and B hold what whole steps give."""
    whole_app, whole = clouds_app(gpu, params())
    warm_app, warm = clouds_app(gpu, params(), warmup_steps=5)
    for _ in range(5):
        whole.job.run_step()
    assert warm.job.step == 2
    for x, y in zip(whole.view()[:2], warm.view()[:2]):
        assert np.array_equal(read_volume(x["density"]), read_volume(y["density"]))
        assert read_volume(x["density"]).any()
    assert whole.sets().wind_travel == warm.sets().wind_travel
    whole_app.close()
    warm_app.close()


def test_density_matches_the_automaton_and_max_maps_never_skip_density(gpu, ctx):
    app, sim = clouds_app(gpu, params())
    for _ in range(25):
        sim.job.run_step()
    a, b, _ = sim.view()
    hum, act, cld = sim.automaton.download()
    expected = reference.smooth(cld, sim.settings.radius, sim.settings.weights, sim.smoother.min_density("f2"))
    assert np.allclose(read_volume(b["density"]), expected, rtol=2**-10, atol=1e-6)
    assert cld.any(), "clouds formed"
    maps = sim.max_maps()
    for band in range(maps.shape[0]):
        for texture_set in (a, b):
            _, ref_max = reference.density_maps(read_volume(texture_set["density"]), sim.settings.band_height,
                                                sim.settings.group_size)
            assert np.all(maps[band][ref_max[band] > 0] > 0), "a segment with density would be skipped"
    app.close()


# the cover is the automaton's and the weather's: the steps of these two tests leave the light out
NO_LIGHT = CloudSettings(smoothing_slices=2, group_size=(8, 8), shading=False)


def test_cover_is_stable_over_1000_steps(gpu, ctx):
    app, sim = clouds_app(gpu, params((64, 8, 64), cloud_density=80), NO_LIGHT)
    covers = []
    for _ in range(1000):
        sim.job.run_step()
        covers.append(sim.cover())
    settled = np.array(covers[150:])
    print(f"cover after warm-up: mean {settled.mean():.3f} std {settled.std():.3f} "
          f"range {settled.min():.3f}..{settled.max():.3f}")
    assert 0.1 < settled.mean() < 0.9
    assert settled.std() < 0.15 * settled.mean()
    assert np.all(np.abs(settled - settled.mean()) < 0.5 * settled.mean())
    app.close()


def rise_steps(gpu, adaption):
    """Steps until the cover first reaches the middle of the way from low to high density."""
    p = params((64, 8, 64), density_adaption=adaption, cloud_density=20, lifetime=400.0, lifetime_variance=50.0)
    app, sim = clouds_app(gpu, p, NO_LIGHT)
    lows = []
    for _ in range(60):
        sim.job.run_step()
        lows.append(sim.cover())
    low = np.mean(lows[-10:])
    next(q for q in app.plugins if isinstance(q, CloudsPlugin)).configure(weather={"cloud_density": 120})
    covers = []
    for _ in range(180):
        sim.job.run_step()
        covers.append(sim.cover())
    high = np.mean(covers[-30:])
    app.close()
    middle = (low + high) / 2
    return next(i for i, c in enumerate(covers) if c >= middle), low, high


def test_density_change_moves_the_cover_at_the_adaption_pace(gpu, ctx):
    slow, low, high = rise_steps(gpu, adaption=1)
    fast, _, _ = rise_steps(gpu, adaption=8)
    print(f"cover {low:.3f} -> {high:.3f}; half-way after {fast} steps (adaption 8), {slow} steps (adaption 1)")
    assert high > 1.6 * low
    assert fast < 25 and slow > 2 * fast


def test_fast_moving_volume_finds_its_clouds_again(gpu, ctx):
    """Flight-simulator holding pattern: the volume circles fast; the region boundings keep the clouds."""
    p = params((64, 8, 64), cloud_density=120, region_margin=32.0, lifetime=1e6, lifetime_variance=0.0,
               shrink_time=0.0, wind=(0.0, 0.0, 0.0))
    app, sim = clouds_app(gpu, p)
    for _ in range(60):
        sim.job.run_step()
    origin = app.resource(VolumeOrigin)
    start = sim.cover()
    laps = 24
    for i in range(1, laps + 1):              # one lap of radius 24 cells: ~6 cells per step, turning
        angle = 2 * np.pi * i / laps
        origin.x, origin.z = 24 * np.sin(angle), 24 * (1 - np.cos(angle))
        sim.job.run_step()
    for _ in range(15):
        sim.job.run_step()
    assert start > 0.1 and sim.cover() > 0.5 * start
    app.close()


@pytest.mark.parametrize("shape", [(1, 1, 1), (37, 5, 19)])
def test_odd_volumes(gpu, ctx, shape):
    app, sim = clouds_app(gpu, params(shape, cloud_size=3.0, cloud_size_variance=1.0, region_margin=2.0),
                          CloudSettings(smoothing_slices=1, group_size=(8, 8)))
    for _ in range(10):
        sim.job.run_step()
    assert np.isfinite(read_volume(sim.view()[1]["density"])).all()
    app.close()


def test_no_clouds_and_very_many_ellipsoids(gpu, ctx):
    app, sim = clouds_app(gpu, params(cloud_density=0))
    for _ in range(20):
        sim.job.run_step()
    assert sim.cover() == 0.0 and not read_volume(sim.view()[1]["density"]).any()
    assert not sim.max_maps().any()
    app.close()
    app, sim = clouds_app(gpu, params(cloud_density=10_000, density_adaption=10_000))
    for _ in range(3):
        sim.job.run_step()
    assert len(app.world.get_component(Ellipsoid)) > 5000
    assert np.isfinite(read_volume(sim.view()[1]["density"])).all()
    app.close()


def test_strong_wind_and_shift_larger_than_the_volume(gpu, ctx):
    app, sim = clouds_app(gpu, params(wind=(7.5, 0.0, -3.0)))
    for _ in range(10):
        sim.job.run_step()
    origin = app.resource(VolumeOrigin)
    origin.x += 1000.0                         # teleport: everything simulated so far leaves the volume
    sim.job.run_step()
    _, _, cld = sim.automaton.download()
    assert not cld.any()
    app.close()


@pytest.mark.parametrize("fields, message", [
    (dict(step_seconds=0.0), "CloudSettings.step_seconds must be a finite number > 0.0"),
    (dict(smoothing_slices=0), r"CloudSettings.smoothing_slices must be a whole number 1\.\.32"),
    (dict(smoothing_slices=33), r"1\.\.32, got 33"),
    (dict(cover_threshold=float("nan")), "CloudSettings.cover_threshold"),
    (dict(layout="dense"), "CloudSettings.layout must be one of 'packed', 'cell'"),
    (dict(shading_scale=3), "CloudSettings.shading_scale must be 1, 2 or 4"),
    (dict(cell_size=(1.0, 0.0, 1.0)), "CloudSettings.cell_size must be 3 positive numbers"),
    (dict(weather={"cloud_size": -1.0}), "WeatherSettings.cloud_size"),
])
def test_bad_settings(fields, message):
    with pytest.raises(ValueError, match=message):
        CloudsPlugin(weather=params(), **fields) if "weather" not in fields else CloudsPlugin(**fields)


def test_live_and_fixed_settings(gpu, ctx):
    app, sim = clouds_app(gpu, params())
    plugin = next(p for p in app.plugins if isinstance(p, CloudsPlugin))
    plugin.configure(weather={"cloud_density": 3}, step_seconds=2.0)
    assert sim.settings is plugin.settings and sim.settings.weather.cloud_density == 3
    before = plugin.settings
    with pytest.raises(ValueError, match=r"CloudSettings\.weather\.volume_shape, CloudSettings\.smoothing_slices "
                                         r"cannot change"):
        plugin.configure(weather={"volume_shape": (16, 8, 16)}, smoothing_slices=4)
    assert plugin.settings is before and sim.settings is before
    app.close()


def test_shading_stage_lights_each_step_with_the_sun_of_its_start(gpu, ctx):
    """Transmittance in a completed set = one-shot shading of that set's density with the sun as it
    was when the step began, however much the sun moved while the step was sliced over frames."""
    from atmos.lighting import Sun
    from atmos.plugins.clouds.light import compute_transmittance
    settings = CloudSettings(smoothing_slices=2, group_size=(8, 8), sigma_t=0.5, cell_size=(2.0, 1.0, 2.0),
                             shading_slices_per_run=4)
    app, sim = clouds_app(gpu, params(), settings)
    sun = Sun.from_angles(30.0, 10.0)
    app.insert_resource(sun)
    for _ in range(20):
        sim.job.run_step()
    start_sun = sim.sun_in_cells()
    step = sim.job.step
    frames = 0
    while sim.job.step == step:               # slice the next step over frames with a moving sun
        sun.direction = Sun.from_angles(30.0 + 2 * frames, 10.0 + 5 * frames).direction
        app.update(1 / 30)
        frames += 1
    assert frames > 5
    _, b, _ = sim.view()
    density = read_volume(b["density"])
    expected = compute_transmittance(gpu, density, start_sun, settings.shading_sigma(start_sun * (2.0, 1.0, 2.0)))
    got = read_volume(b["transmittance"])
    assert density.max() > 0.5 and got.min() < 0.9, "clouds cast light shadows"
    assert np.abs(got - expected).max() < 2e-3        # f2 storage
    app.close()


def test_volume_larger_than_the_gpu_allows_is_a_clear_error(gpu, ctx):
    app = App(gpu)
    with pytest.raises(ValueError, match="too big for this GPU"):
        app.add_plugins(CloudsPlugin(weather=params((8192, 64, 8192))))
    app.close()
