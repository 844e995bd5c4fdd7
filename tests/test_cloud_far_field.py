"""Clouds to the horizon: the volume's edge fade, the far field's cover, and the sunset horizon by pixels."""
import dataclasses
import math
import types

import numpy as np
import pytest

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
from atmos.plugins.clouds.far_field.layer import profile_heights
from atmos.plugins.clouds.far_field.reference import column_profile, column_quantiles, light_by_rank, volume_cover
from atmos.plugins.clouds import CloudSimulation, CloudsPlugin
from atmos.plugins.clouds.volume.edge import edge_weight
from atmos.plugins.clouds.simulation.smoothing import read_volume
from atmos.runner import build_app


def test_edge_weight_is_one_inside_zero_on_the_circle_and_smooth():
    uv = np.stack([np.linspace(0.5, 1.0, 101), np.full(101, 0.5)], -1)
    w = edge_weight(uv, 0.4)
    assert w[0] == 1.0 and w[60] == 1.0 and w[-1] == 0.0
    assert np.all(np.diff(w) <= 0.0) and np.abs(np.diff(w)).max() < 0.05       # no step
    assert edge_weight([[1.0, 1.0]], 0.4)[0] == 0.0                             # the square's corners are gone
    assert np.all(edge_weight(np.random.default_rng(0).random((50, 2)), 0.0) == 1.0)


def check_profile_matches_numpy(layer, sets, fade):
    """cover.comp's vertical profile by rank of mix(A, B, t) against column_profile (ranked by the GPU's
    quantiles): each interval's shape R per unit column sum and share above G; and it is the volume's
    shape (the clouds of this volume sit mid-layer: little density in the lowest and highest quarter).
    A sprite scene measures no profile (only a march's far field uses it): measured here on request."""
    assert layer.profile is None, "no profile measured for the sprites"
    layer.measure_cover(sets, profile=True)
    gpu_profile = layer.read_profile()
    _, quantiles = layer.read_cover()
    density = [read_volume(s["density"]) for s in (sets.a, sets.b)]
    ref = column_profile(density[0], density[1], sets.t, sets.a_shift, fade, quantiles)
    assert gpu_profile.shape == ref.shape == (32, sets.shape[1], 2)
    ny = sets.shape[1]
    assert np.allclose(gpu_profile[..., 0].sum(1), 1.0, atol=1e-4), "R sums to one column sum"
    off = np.abs(gpu_profile - ref).max(axis=(1, 2)) / np.maximum(ref[..., 0].max(1), 1e-6)
    assert np.median(off) < 0.01 and off.max() < 0.05, off        # an interval's edge may hold a column more or less
    weight = gpu_profile[..., 0].mean(0)
    assert weight[: ny // 4].sum() + weight[-(ny // 4):].sum() < 0.25, weight


def test_sunset_has_clouds_below_9_degrees_around_the_sun_and_cover_matches_numpy():
    gpu = create_headless((160, 90))
    app = build_app("sunset", DemoSettings(size=gpu.size, headless=True, clouds="sprites"), gpu, start=False)
    try:
        from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
        next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin)).configure(enabled=False)  # the 2D far field
        app.startup()
        app.run_frames(4, 1 / 30)
        far = next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin))
        sim = app.resource(CloudSimulation)
        sets = sim.sets()
        gpu_cover, gpu_columns = far.layer.read_cover()
        sums = [sets.maps_of(s).read_sums()[0] for s in (sets.a, sets.b)]
        assert sets.a is not sets.b and 0.0 < sets.t < 1.0, "a frame between two steps"
        fade, threshold, t = sim.settings.edge_fade, sim.settings.cover_threshold, sets.t
        # measured once per step of each set alone (A's kept from when it was B), mixed at the frame's t
        alone = [volume_cover(s, s, 1.0, (0, 0, 0), threshold, fade) for s in sums]
        expected = (1.0 - t) * alone[0] + t * alone[1]
        assert 0.0 < expected < 1.0 and abs(gpu_cover - expected) < 1e-4, (gpu_cover, expected)
        of_mix = volume_cover(sums[0], sums[1], t, sets.a_shift, threshold, fade)
        assert abs(gpu_cover - of_mix) < 0.02, (gpu_cover, of_mix)          # the cover mix(A, B, t) shows
        # the column-sum quantiles the march's far field takes (cover.comp's histogram: within a bin),
        # mixed rank by rank; their mean is the mean column of mix(A, B, t)
        columns = sum(w * column_quantiles(s, s, 1.0, (0, 0, 0), fade) for w, s in zip((1.0 - t, t), sums))
        bin_width = sets.shape[1] / 256
        assert columns[-1] > 1.0 and np.all(np.diff(gpu_columns) >= 0.0)
        assert np.abs(gpu_columns - columns).max() < 1.5 * bin_width, np.c_[gpu_columns, columns]
        shown = column_quantiles(sums[0], sums[1], t, sets.a_shift, fade)
        assert abs(np.trapezoid(gpu_columns, dx=1 / 32) - np.trapezoid(shown, dx=1 / 32)) < 1.5 * bin_width
        assert abs(np.mean(gpu_columns > threshold) - expected) < 2.0 / 32   # covered at the same ranks
        check_profile_matches_numpy(far.layer, sets, fade)
        cam = app.resource(Camera)
        with_far = app.read_linear()
        far.configure(enabled=False)
        app.render()
        without = app.read_linear()
        # rows of the sky between 0.5° and 9° above the horizon (the camera's pitch is 7°)
        rows = np.arange(gpu.size[1])
        elevation = cam.pitch + np.arctan((1.0 - 2.0 * (rows + 0.5) / gpu.size[1]) * math.tan(cam.fov_y / 2))
        band = (elevation > math.radians(0.5)) & (elevation < math.radians(9.0))
        changed = np.abs(with_far[band, :, :3] - without[band, :, :3]).max(-1) > 0.02
        assert changed.mean() > 0.05, f"only {changed.mean():.1%} of the low sky has far-field clouds"
    finally:
        app.close()
        gpu.release()


def test_the_far_field_is_measured_once_per_step_of_each_set_and_mixed_each_frame():
    """Sunset with the march (cover, profile and light by rank all measured): a set is measured alone
    when first shown as B and kept while it is A (no measure in a frame without a new step), and
    again when the settings the measure takes change; each frame's measure is A's and B's mixed at the
    frame's t (rank_mix.comp, to float32's rounding); B's own cover is its float64 cover."""
    from atmos.plugins.clouds.far_field.layer import RankMeasure, _transitions
    gpu = create_headless((96, 54))
    app = build_app("sunset", DemoSettings(size=gpu.size, headless=True), gpu)
    try:
        app.run_frames(2, 1 / 30)
        far = next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin))
        sim, layer = app.resource(CloudSimulation), far.layer
        measured = []
        real = layer.measure_cover

        def counted(sets, profile=None, into=None):
            measured.append((sets.b, into))
            return real(sets, profile, into)
        layer.measure_cover = counted
        last, steps, between = (sim.sets().b, sim.sets().b.version), 0, None
        for _ in range(40):
            before = len(measured)
            app.update(1 / 30)
            sets = sim.sets()
            new_step = (sets.b, sets.b.version) != last
            last, steps = (sets.b, sets.b.version), steps + new_step
            assert len(measured) - before == int(new_step), "one measure per new B, none between steps"
            if new_step:
                assert measured[-1][0] is sets.b and isinstance(measured[-1][1], RankMeasure)
            if 0.2 < sets.t < 0.8 and sets.a is not sets.b:
                between = sets
                frame = (np.frombuffer(layer.cover.read(), np.float32), layer.read_profile(), layer.light.read())
                own = {m.of[0]: m for m in layer._steps if m.of is not None}
                parts = [(np.frombuffer(own[x].cover.read(), np.float32), read_rank(own[x].profile), own[x].light.read())
                         for x in (sets.a, sets.b)]
        assert steps >= 2 and between is not None, (steps, between)
        t = between.t
        for got, a, b in zip(frame[:2], parts[0][:2], parts[1][:2]):
            want = (1.0 - t) * a.astype(np.float64) + t * b.astype(np.float64)
            assert np.abs(got - want).max() <= 1e-6 * max(np.abs(want).max(), 1.0)
        assert set(frame[2]) == set(parts[0][2]) and "sun_profile" in frame[2]
        for name, got in frame[2].items():
            want = (1.0 - t) * parts[0][2][name] + t * parts[1][2][name]
            assert np.abs(got - want).max() <= 1e-6 * max(np.abs(want).max(), 1.0), name
        sums = between.maps_of(between.b).read_sums()[0]
        own_cover = volume_cover(sums, sums, 1.0, (0, 0, 0), sim.settings.cover_threshold, sim.settings.edge_fade)
        assert abs(parts[1][0][0] - own_cover) < 1e-4 and _transitions(layer._steps[0].cover)[1] >= 0.0
        before = len(measured)
        far.configure(enabled=False)        # no far field drawn: neither its shape nor its light taken
        app.update(1 / 30)
        sets = sim.sets()
        again = {id(b) for b, _ in measured[before:]}
        assert {id(sets.a), id(sets.b)} <= again, "a new key: both shown sets measured anew"
    finally:
        app.close()
        gpu.release()


def read_rank(texture):
    from atmos.plugins.clouds.far_field.columns import read_rank_texture
    return read_rank_texture(texture)


@pytest.mark.parametrize("shape, base", [((16, 8, 16), 0.25), ((16, 80, 16), 0.6), ((16, 8, 16), None)])
def test_the_profile_by_rank_is_the_volumes_vertical_shape(gpu, ctx, shape, base):
    """cover.comp's profile for static volumes against column_profile: clouds whose height grows with
    their thickness, centred at ``base`` of the layer (80 cells: 64 samples, the nearest cell); None:
    no cloud at all (uniform R, no NaN)."""
    from atmos import App, DefaultPlugins
    from atmos.plugins.clouds import CloudSettings, CloudsPlugin
    nx, ny, nz = shape
    d = np.zeros(shape, np.float32)
    if base is not None:
        x, z = np.meshgrid(np.arange(nx), np.arange(nz), indexing="ij")
        thick = (0.05 + 0.25 * ((x + 2 * z) % 7) / 6.0) * ((x // 4 + z // 4) % 2 == 0)   # half the columns
        h = (np.arange(ny) + 0.5) / ny
        d[:] = np.exp(-0.5 * ((h[None, :, None] - base) / np.maximum(thick[:, None, :], 1e-3)) ** 2) * (thick[:, None, :] > 0)
    medium = CloudSettings(cell_size=(40.0, 40.0, 40.0), base_altitude=400.0, group_size=(4, 4), smoothing_slices=1,
                           sigma_t=0.02, edge_fade=0.2)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium, density=d), CloudFarFieldPlugin(size=64))
    try:
        app.startup()
        app.render()
        far = next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin))
        sets = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation.sets()
        far.layer.measure_cover(sets, profile=True)
        _, quantiles = far.layer.read_cover()
        got = far.layer.read_profile()
        density = [read_volume(s["density"]) for s in (sets.a, sets.b)]
        want = column_profile(density[0], density[1], sets.t, sets.a_shift, 0.2, quantiles, heights=min(ny, 64))
        assert got.shape == want.shape == (32, min(ny, 64), 2) and np.isfinite(got).all()
        assert np.abs(got - want).max() < 1e-3 * max(want[..., 0].max(), 1.0) + 1e-4, np.abs(got - want).max()
        if base is None:
            assert np.allclose(got[..., 0], 1.0 / ny)
        else:
            heights = (np.arange(got.shape[1]) + 0.5) / got.shape[1]
            centre = (got[..., 0] * heights).sum(1) / got[..., 0].sum(1)
            columns = d.transpose(0, 2, 1)[d.sum(1) > 0]              # (n, ny): the covered columns
            own = (columns * (np.arange(ny) + 0.5) / ny).sum(1) / columns.sum(1)
            assert own.min() - 0.02 < centre.min() and centre.max() < own.max() + 0.02, (centre, own)   # where the volume's clouds sit
            assert abs(centre.mean() - base) < abs(centre.mean() - 0.5) or base == 0.5
            spread = np.sqrt((got[..., 0] * (heights - centre[:, None]) ** 2).sum(1) / got[..., 0].sum(1))
            assert spread[-1] > 1.5 * spread[-16], spread              # thicker columns, taller clouds
    finally:
        app.close()


LIGHT_MEDIUM = dict(cell_size=(40.0, 30.0, 40.0), base_altitude=400.0, smoothing_slices=1, sigma_t=0.03)


def light_scene(gpu, density, edge_fade: float, group=(4, 4), far_size: int = 64, sun=None):
    """A static volume drawn by the sprites (the diffusion field on) with a far field, rendered once:
    (app, the CloudFarFieldPlugin, the frame's CloudSets). The caller closes the app."""
    from atmos import App, DefaultPlugins
    from atmos.plugins.clouds.sprites import CloudRenderPlugin
    from atmos.plugins.clouds import CloudSettings
    medium = CloudSettings(group_size=group, edge_fade=edge_fade, **LIGHT_MEDIUM)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium, density=density),
                               CloudRenderPlugin(ms_diffusion=1.0), CloudFarFieldPlugin(size=far_size))
    if sun is not None:
        app.insert_resource(sun)
    app.startup()
    app.render()
    far = next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin))
    return app, far, next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation.sets()


def light_reference(far, sets) -> dict:
    """light_by_rank (float64) of the sets' textures as the GPU holds them, ranked by its quantiles."""
    from atmos.plugins.clouds.volume.light import cell_tau
    from atmos.plugins.clouds.light.diffusion import DIFFUSION, read_field
    from atmos.plugins.clouds.light.medium import octave_parameters
    _, quantiles = far.layer.read_cover()
    a, b = sets.a, sets.b
    return light_by_rank(*(sets.maps_of(s).read_sums()[0] for s in (a, b)), *(read_volume(s["density"]) for s in (a, b)),
                         sets.t, sets.a_shift, sets.settings.edge_fade, quantiles, heights=profile_heights(sets.shape[1]),
                         attenuation=octave_parameters(far.light_settings().octaves, sets.settings)[0], column_tau=cell_tau(sets.settings),
                         trans_a=read_volume(a["transmittance"]), trans_b=read_volume(b["transmittance"]),
                         field_a=read_field(a[DIFFUSION]), field_b=read_field(b[DIFFUSION]))


def assert_light_matches(got, want, names) -> None:
    for name in names:
        assert got[name].shape == want[name].shape and np.isfinite(got[name]).all(), name
        err = np.abs(got[name] - want[name]).max()
        assert err < 5e-3 * max(np.abs(want[name]).max(), 1e-3), (name, err)


@pytest.mark.parametrize("clouds", [True, False])
def test_the_light_by_rank_is_the_volumes_own_light(gpu, ctx, rng, clouds):
    """light_by_rank.comp (RankLight) against its float64 reference on a fresh random volume: per rank
    interval the octaves' mean sun transmittances and the diffusion field's mean (phi, F), seen from
    above and from below, both per height bin, the height that light comes from, and the clouds' thickness; the sun lower than the cloud
    tops shades the bases. No cloud at all: T = 1, the field 0, the thickness the layer's, nothing NaN."""
    from atmos.lighting import Sun
    shape = (16, 12, 16)
    d = np.zeros(shape, np.float32)
    if clouds:
        x, y, z = np.meshgrid(*[np.arange(k) + 0.5 for k in shape], indexing="ij")
        for _ in range(6):
            c, r = rng.uniform([2, 3, 2], [14, 9, 14]), rng.uniform(2.0, 5.0)
            d = np.maximum(d, np.clip(1.0 - ((x - c[0]) ** 2 + ((y - c[1]) * 1.5) ** 2 + (z - c[2]) ** 2) / r ** 2, 0, 1))
    sun = Sun.from_angles(float(rng.uniform(15.0, 60.0)), float(rng.uniform(0.0, 360.0)))
    app, far, sets = light_scene(gpu, d, 0.2, sun=sun)
    try:
        got = far.layer.light.read()
        assert set(got) == {"sun", "height", "thickness", "sun_profile", "field", "field_profile"}, "the renderer gives the field a weight: measured"
        assert_light_matches(got, light_reference(far, sets), ("sun", "height", "thickness", "sun_profile", "field", "field_profile"))
        far.configure(enabled=False)          # the ground shadows alone still prepare the layer
        far.layer.light.release()
        far.layer.prepare(types.SimpleNamespace(sun=sun, time=0.0), sets)
        assert far.layer.light.sun is None, "no far field drawn: its light is not measured"
        if clouds:
            _, quantiles = far.layer.read_cover()
            covered = quantiles[:-1] > 1e-6
            assert covered.sum() >= 4 and got["field"][..., 0].max() > 0.05, "the volume scatters light"
            above, below = got["sun"][covered, 0, 0], got["sun"][covered, 1, 0]
            assert below.mean() < above.mean(), f"the bases are in the clouds' own shadow: {above} vs {below}"
            assert np.all((got["sun"] >= 0) & (got["sun"] <= 1))
            profile = got["sun_profile"][covered, :, 0]
            assert np.ptp(profile, axis=1).max() > 0.05 and np.all((profile >= 0) & (profile <= 1)), "it varies by height"
            assert np.all((got["thickness"] > 0) & (got["thickness"] <= 1)) and got["thickness"][covered].min() < 0.9
            top, base = got["height"][covered, 0], got["height"][covered, 1]
            # the random blobs' mean gap was 0.046-0.22 over 26 seeds (4066623735: 0.046), the largest per
            # interval 0.13-0.53: every interval at least as high from above, some clearly higher
            assert np.all((top >= base - 1e-6) & (base >= 0) & (top <= 1)) and (top - base).max() > 0.1, \
                f"seen from above, the light comes from higher up: {top} vs {base}"
        else:
            assert np.all(got["sun"] == 1.0) and np.all(got["sun_profile"] == 1.0) and np.all(got["field"] == 0.0)
            assert np.all(got["thickness"] == 1.0) and np.all(got["height"] == 0.5)
    finally:
        app.close()


def far_scene(gpu, **far):
    """A static volume (half its columns clouded, in 4-cell blocks) with a far field; rendered once."""
    from atmos import App, DefaultPlugins
    from atmos.plugins.clouds import CloudSettings, CloudsPlugin
    d = np.zeros((32, 8, 32), np.float32)
    x, z = np.meshgrid(np.arange(32), np.arange(32), indexing="ij")
    d[:, 2:6] = ((x // 4 + z // 4) % 2 == 0)[:, None, :]
    medium = CloudSettings(cell_size=(40.0, 40.0, 40.0), base_altitude=400.0, group_size=(4, 4), smoothing_slices=1,
                           sigma_t=0.02, edge_fade=0.2)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium, density=d), CloudFarFieldPlugin(**far))
    app.startup()
    app.render()
    return app


def correlation(a, b) -> float:
    a, b = a - a.mean(), b - b.mean()
    return float((a * b).mean() / max(a.std() * b.std(), 1e-12))


@pytest.mark.parametrize("pitch", [0.25, 0.7])
def test_the_far_fields_opacity_matches_float64(gpu, ctx, filter_bits, pitch):
    """far.comp's alpha outside the volume (mip 0: a 64-texel, 20 km tile) against far_field_alpha: the
    column optical depth at the middle plane's hit, at the rank and scale slant_rank gives for clouds of
    the measured height (RankLight's thickness at the median covered rank) at the ray's slant, over the
    slant, times the horizon fade; as a flat layer (height 0) it is far off (the test can fail)."""
    from atmos.plugins.clouds.far_field.cover import fbm_quantiles, pattern_crossings
    from atmos.plugins.clouds.far_field.layer import column_tau, drift
    from atmos.plugins.clouds.far_field.reference import far_field_alpha
    from atmos.plugins.clouds.raymarch.reference import rays
    app = far_scene(gpu, size=64, tile_size=20000.0, animate=False)
    try:
        far = next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin))
        sets = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation.sets()
        cam = app.resource(Camera)
        cam.position, cam.yaw, cam.pitch = np.array([-3000.0, 200.0, 300.0]), -math.pi / 2, pitch   # looking away
        cam.near, cam.far = 1.0, 40000.0
        alpha = app.read_linear()[::-1, :, 3].astype(np.float64)
        layer, params = far.layer, far.settings
        layout = sets.layout()
        cover, columns = layer.read_cover()
        thickness = layer.light.read()["thickness"]
        height = (layout.hi[1] - layout.lo[1]) * np.interp(1.0 - 0.5 * cover, (np.arange(32) + 0.5) / 32, thickness)
        dirs, _ = rays(cam, gpu.size)
        s = (0.5 * (layout.lo[1] + layout.hi[1]) - cam.position[1]) / dirs[..., 1]
        xz = cam.position[[0, 2]] + s[..., None] * dirs[..., [0, 2]]
        fade = np.clip(np.abs(dirs[..., 1]) / params.horizon_fade, 0.0, 1.0)
        fade = fade * fade * (3.0 - 2.0 * fade)
        args = ([layer.octaves.download(k) for k in range(4)], drift(params, sets, 0.0, layer.tile_size), layer.tile_size,
                fbm_quantiles(params.base_frequency, params.seed, params.size), columns, column_tau(params, sets), cover,
                pattern_crossings(params.base_frequency, params.seed, params.size))
        fade = np.where(s > 0.0, fade, 0.0)                 # below the plane: none
        want = far_field_alpha(xz, dirs, height, *args, weight_bits=filter_bits) * fade   # as this GPU filters
        flat = far_field_alpha(xz, dirs, 0.0, *args) * fade
        texels = params.size / layer.tile_size * 2.0 * math.tan(cam.fov_y / 2) / gpu.size[1] * s / np.abs(dirs[..., 1])
        mip0 = (s > 0.0) & (texels < 1.0)                   # far.comp's footprint: mip 0 (nearer the horizon coarser)
        assert mip0.mean() > 0.3 and 0.2 < (want[mip0] > 0.05).mean() < 0.95, "the view holds far clouds and gaps"
        err = np.abs(alpha - want)[mip0]
        assert np.percentile(err, 99) < 0.02 and err.mean() < 0.004, (err.mean(), np.percentile(err, 99))
        assert np.abs(alpha - flat)[mip0].mean() > 5 * err.mean(), "the clouds' sides are seen"
        # the reference filters the octaves as this GPU's texture unit does (filter_bits): 8-bit sub-texel
        # weights (a machine with an NVIDIA GPU) move the fbm by up to 1/512 of a texel's difference, and the
        # rank, steep in it between two quantiles, with it: the exact and the 8-bit filter differ beyond the limit
        exact, coarse = (far_field_alpha(xz, dirs, height, *args, weight_bits=b) * fade for b in (None, 8))
        assert np.percentile(np.abs(coarse - exact)[mip0], 99) > 0.02, "the filter's precision does not matter here"
    finally:
        app.close()


def test_a_sun_and_sky_of_1e30_saturate_the_far_field_below_float16s_largest(gpu, ctx):
    """CloudSettings.sun_intensity and sky_intensity have no upper bound: at 1e30 far.comp's light is held
    at HDR_MAX (lib/hdr_max.glsl), below float16's 65504, so the colour target stays finite (a machine
    with an NVIDIA GPU rounds past 65504 to inf; Mesa's llvmpipe toward zero, to 65504: caught here)."""
    from test_cloud_render import assert_a_1e30_sun_and_sky_saturate
    app = far_scene(gpu, size=64, tile_size=20000.0, animate=False)
    try:
        cam = app.resource(Camera)
        cam.position, cam.yaw, cam.pitch = np.array([-3000.0, 200.0, 300.0]), -math.pi / 2, 0.25   # the far field alone
        cam.near, cam.far = 1.0, 40000.0
        assert_a_1e30_sun_and_sky_saturate(app)
    finally:
        app.close()


def test_the_far_fields_cover_repeats_at_no_tile_lag(gpu, ctx):
    """The cover (fbm above its median) of the pattern drawn (the GPU's baked octaves, each turned and
    with its own period: pattern.py) correlates along x and along z at lags of 1, 2, 3 tiles no more
    than at lags between them; with one period and no turn for all octaves it repeated exactly (1.0)."""
    from atmos.plugins.clouds.far_field.layer import drift
    from atmos.plugins.clouds.far_field.reference import field_fbm
    app = far_scene(gpu, size=128, tile_size=1000.0, animate=False)
    try:
        far = next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin))
        sets = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation.sets()
        layer, tile = far.layer, 1000.0
        octaves = [layer.octaves.download(k) for k in range(4)]
        offsets = drift(far.settings, sets, 0.0, tile)
        xs = np.arange(0.0, 4.0 * tile, tile / 32.0)
        across = np.arange(64) * 0.377 * tile
        line = lambda lag, axis: np.stack(np.broadcast_arrays(*((xs[None, :] + lag, across[:, None])[::1 - 2 * axis])), -1)
        tile_lags, other_lags = (1.0, 2.0, 3.0), (0.63, 1.37, 1.61, 2.29, 2.71, 3.45)
        for axis in (0, 1):
            base = field_fbm(line(0.0, axis), octaves, offsets, tile)
            cover = lambda f: (f > np.median(base)).astype(np.float64)
            acf = {lag: correlation(cover(base), cover(field_fbm(line(lag * tile, axis), octaves, offsets, tile)))
                   for lag in tile_lags + other_lags}
            at_tiles, between = max(acf[l] for l in tile_lags), max(abs(acf[l]) for l in other_lags)
            assert at_tiles < between + 0.05 and at_tiles < 0.3, (axis, acf)
        # every octave drifts by the same world distance: the pattern after t seconds of wind is the
        # pattern at 0 carried along by wind * t
        windy = dataclasses.replace(far.settings, wind=(7.0, -3.0))
        xz = line(0.0, 0)
        moved = field_fbm(xz, octaves, drift(windy, sets, 1000.0, tile), tile)
        assert np.allclose(moved, field_fbm(xz + np.array([7000.0, -3000.0]), octaves, drift(windy, sets, 0.0, tile), tile), atol=1e-9)
    finally:
        app.close()


def test_the_far_fields_clouds_change_as_often_per_metre_as_the_volumes(gpu, ctx):
    """tile_size None: the layer's tile is chosen from the volume's cover transitions (cover.comp, against
    volume_transitions in float64), so the cover drawn (column sum at the rank above the cover threshold,
    the GPU's octaves in float64) changes along a line as often per metre as the volume's, within 15 %;
    a fixed 8 km tile (the old default) made the far field's clouds 2.5-3x wider."""
    from atmos.plugins.clouds.far_field.cover import fbm_quantiles
    from atmos.plugins.clouds.far_field.layer import drift
    from atmos.plugins.clouds.far_field.reference import column_at_rank, field_fbm, field_rank, volume_transitions
    app = far_scene(gpu, size=128, animate=False)
    try:
        far = next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin))
        sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation
        sets = sim.sets()
        layer = far.layer
        cover, transitions = layer.read_transitions()
        sums = [sets.maps_of(s).read_sums()[0] for s in (sets.a, sets.b)]
        want = volume_transitions(sums[0], sums[1], sets.t, sets.a_shift, sim.settings.cover_threshold, 0.2)
        assert 0.05 < want < 0.5 and abs(transitions - want) < 1e-4, (transitions, want)
        volume_rate = want / 40.0                                        # per metre
        tile = layer.tile_size
        octaves = [layer.octaves.download(k) for k in range(4)]
        _, columns = layer.read_cover()
        xs = np.arange(0.0, 12.0 * tile, 20.0)
        lines = np.stack(np.broadcast_arrays(xs[None, :], (np.arange(48) * 0.613 * tile)[:, None]), -1)
        rates = []
        for pts in (lines, lines[..., ::-1]):
            rank = field_rank(field_fbm(pts, octaves, drift(far.settings, sets, 0.0, tile), tile),
                              fbm_quantiles(far.settings.base_frequency, far.settings.seed, far.settings.size))
            covered = column_at_rank(rank, columns) > sim.settings.cover_threshold
            assert abs(covered.mean() - cover) < 0.1, (covered.mean(), cover)
            rates.append(np.diff(covered, axis=-1).mean() / 20.0)
        assert abs(np.mean(rates) / volume_rate - 1.0) < 0.15, (np.mean(rates), volume_rate, tile)
    finally:
        app.close()


@pytest.mark.parametrize("shape", [(1, 1, 1), (192, 8, 192)])
def test_the_light_by_rank_of_a_one_cell_and_a_wide_uniform_deck_is_finite(gpu, ctx, shape):
    """Extremes of light_by_rank.comp: one cell (against the float64 twin), and a deck of 36,864 equal
    columns that all fall in one rank interval (the fixed-point sums sized so that none overflows): T
    within [0, 1], the field finite, and the deck's mean T seen from above and below its columns' own
    (every column weighs its samples alike, so the mean over all columns of each row's T, weighted);
    the deck's clouds as high as the layer; the far field drawn over the whole sky from a grazing sun
    to one below the horizon, finite (a cover of 1: nothing to widen at a slant)."""
    app, far, sets = light_scene(gpu, np.ones(shape, np.float32), 0.0, group=(1, 1) if shape[0] == 1 else (8, 8),
                                 far_size=32)
    try:
        got = far.layer.light.read()
        for name, values in got.items():
            assert np.isfinite(values).all(), name
        assert np.all((got["sun"] >= 0.0) & (got["sun"] <= 1.0))
        assert got["field"][..., 0].max() > 0.0, "the cloud scatters light"
        T = read_volume(sets.b["transmittance"]).astype(np.float64)
        assert np.all((got["sun_profile"] >= 0.0) & (got["sun_profile"] <= 1.0)) and got["thickness"].max() <= 1.0
        if shape == (1, 1, 1):
            assert_light_matches(got, light_reference(far, sets), ("sun", "height", "thickness", "sun_profile", "field"))
        else:
            assert T.shape == shape and sets.t in (0.0, 1.0)
            tau = 0.03 * 30.0 * np.ones(shape[1])                      # each row's optical depth, density 1
            below = np.cumsum(tau)
            rows = T.mean(axis=(0, 2))                                    # every column alike: the rows' mean T
            for view, seen in enumerate((np.exp(-(below[-1] - below + 0.5 * tau)), np.exp(-(below - 0.5 * tau)))):
                want = (seen * rows).sum() / seen.sum()
                assert abs(got["sun"][-1, view, 0] - want) < 2e-3, (view, got["sun"][-1, view, 0], want)
            assert got["sun"][-1, 1, 0] < got["sun"][-1, 0, 0]
            assert abs(got["thickness"][-1] - 1.0) < 1e-3, got["thickness"][-1]
            from atmos.lighting import Sun
            cam = app.resource(Camera)
            cam.position, cam.yaw, cam.pitch = np.array([0.0, 100.0, 0.0]), 0.4, 0.05
            for elevation in (0.5, 0.0, -3.0):
                app.insert_resource(Sun.from_angles(elevation, 80.0))
                app.render()
                image = app.read_linear()
                assert np.isfinite(image).all(), elevation
    finally:
        app.close()
