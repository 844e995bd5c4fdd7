"""Issue 12's outside-comparison API: static clouds from a given density volume, the linear HDR
readback, and no sky light without a sky (``Sun.ambient = 0``)."""
import math

import numpy as np
import pytest

from atmos import App, DefaultPlugins
from atmos.camera import Camera, view_basis
from atmos.lighting import Sun
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.clouds.weather import VolumeOrigin
from atmos.render_core import CapturePass, RenderCorePlugin, tone_map

SHAPE = (16, 4, 16)
CELL = (20.0, 30.0, 25.0)
BASE = 400.0
ORIGIN = (3.0, 0.0, -2.0)                 # in cells (x, z): the layout puts cell i at (ox + i + 0.5) * cx
BLOCK = (slice(2, 7), slice(0, 4), slice(9, 14))


def block_density():
    d = np.zeros(SHAPE, np.float32)
    d[BLOCK] = 1.0
    return d


def static_app(gpu, density, march=False, sun=Sun.from_angles(40.0, 70.0), **medium):
    settings = CloudSettings(cell_size=CELL, base_altitude=BASE, group_size=(8, 8), smoothing_slices=1,
                             sigma_t=medium.pop("sigma_t", 0.02), **medium)
    renderer = RaymarchCloudsPlugin.reference() if march else CloudRenderPlugin(downsample=1)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(settings, density=density), renderer)
    origin = app.resource(VolumeOrigin)             # the one the clouds follow: moved, not replaced
    origin.x, origin.z = ORIGIN[0], ORIGIN[2]
    app.insert_resource(sun)
    app.startup()
    return app


def aim(app, position, target):
    cam = app.resource(Camera)
    cam.position = np.array(position, float)
    cam.look_at(np.array(target, float))
    cam.near, cam.far = 1.0, 20000.0
    return cam


def box_hits(cam, size, lo, hi):
    """(h, w) bool: the pixel-centre rays that cross the world box [lo, hi] (first row at the top)."""
    w, h = size
    xs = 2 * (np.arange(w) + 0.5) / w - 1
    ys = 1 - 2 * (np.arange(h) + 0.5) / h
    ndc = np.stack(np.broadcast_arrays(xs[None, :], ys[:, None], 1.0), -1)
    d = ndc @ view_basis(cam, w / h).T
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (lo - cam.position) / d, (hi - cam.position) / d
    near = np.minimum(t0, t1).max(-1)
    far = np.maximum(t0, t1).min(-1)
    return far > np.maximum(near, 0.0)


@pytest.mark.parametrize("march", [False, True], ids=["sprites", "march"])
def test_static_clouds_sit_where_the_documented_layout_puts_them(gpu, ctx, march):
    app = static_app(gpu, block_density(), march=march)
    cell = np.array(CELL)
    lo_cells = np.array([BLOCK[0].start + ORIGIN[0], BLOCK[1].start, BLOCK[2].start + ORIGIN[2]])
    hi_cells = np.array([BLOCK[0].stop + ORIGIN[0], BLOCK[1].stop, BLOCK[2].stop + ORIGIN[2]])
    lo = lo_cells * cell + [0, BASE, 0]
    hi = hi_cells * cell + [0, BASE, 0]
    center = (lo + hi) / 2
    for offset in ([0.0, 250.0, 700.0], [-600.0, -300.0, 200.0]):
        cam = aim(app, center + offset, center)
        image = app.read_linear()
        cloud = image[..., :3].sum(-1) > 0.02 * image[..., :3].sum(-1).max()
        hits = box_hits(cam, gpu.size, lo, hi)
        assert hits.any() and cloud.any()
        iou = (cloud & hits).sum() / (cloud | hits).sum()
        # the density ramps to 0 over half a cell past the block (trilinear), sprites are round
        assert iou > (0.55 if not march else 0.7), f"cloud pixels vs the layout's box: IoU {iou:.2f}"
        ys, xs = np.nonzero(cloud)
        hy, hx = np.nonzero(hits)
        assert abs(ys.mean() - hy.mean()) < 3 and abs(xs.mean() - hx.mean()) < 3, "the cloud is off its place"
    app.close()


@pytest.mark.parametrize("density, what", [
    (np.zeros((4, 4)), "shape"),
    (np.zeros((4, 0, 4)), "shape"),
    ("clouds", "dtype"),
    (np.zeros((2, 2, 2), complex), "dtype"),
    (np.full((2, 2, 2), np.nan), "finite"),
    (np.full((2, 2, 2), 1e39), "finite"),
    (-np.ones((2, 2, 2)), ">= 0"),
])
def test_bad_density_arrays_are_refused_by_the_plugin_with_what_is_allowed(density, what):
    with pytest.raises(ValueError, match="density") as info:
        CloudsPlugin(density=density)
    assert what in str(info.value)


def test_read_linear_is_the_hdr_colour_before_exposure_first_row_at_the_top(gpu, ctx):
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin())
    app.startup()
    cam = aim(app, (0.0, 10.0, 0.0), (100.0, 40.0, 0.0))     # sky above, its horizon band below
    capture = app.graph.add_pass(CapturePass())
    core = next(p for p in app.plugins if isinstance(p, RenderCorePlugin))
    core.configure(exposure=3.0, dither=False)
    linear = app.read_linear()
    assert linear.dtype == np.float32 and linear.shape == (gpu.size[1], gpu.size[0], 4)
    assert np.array_equal(linear, capture.color[::-1].astype(np.float32)), "the same frame as a CapturePass"
    assert not np.allclose(linear[0], linear[-1]), "a gradient, so the row order is tested"
    shown = gpu.read_pixels() / 255.0
    assert np.abs(tone_map(linear[..., :3], 3.0) - shown).max() < 1.5 / 255, "exposure applies after"
    assert np.abs(tone_map(linear[..., :3], 1.0) - shown).max() > 10 / 255
    assert cam is app.resource(Camera)
    app.close()


def test_without_sky_light_the_clouds_get_none(gpu, ctx):
    """Sun.ambient = (0, 0, 0), no sky plugin, sun under the horizon: nothing lights the clouds."""
    density = block_density()
    for march in (False, True):
        images = {}
        for ambient in ((0.0, 0.0, 0.0), (0.3, 0.4, 0.6)):
            sun = Sun.from_angles(-8.0, 70.0)
            sun.ambient = ambient
            app = static_app(gpu, density, march=march, sun=sun)
            center = (np.array([4.5 + ORIGIN[0], 2.0, 11.5 + ORIGIN[2]]) * CELL) + [0, BASE, 0]
            aim(app, center + [0.0, -250.0, 600.0], center)
            images[ambient] = app.read_linear()[..., :3]
            app.close()
        lit = images[(0.3, 0.4, 0.6)]
        assert lit.max() > 0.05, "with sky light the clouds show"
        assert np.abs(images[(0.0, 0.0, 0.0)]).max() == 0.0, "without it they are black"


def test_sprite_image_does_not_grow_with_the_size_factor(gpu, ctx):
    """The sprites spread each block's optical depth like its mass (the hat's spread), cut off at the
    size factor's radius: the image sum stays with the ray march's of the same volume whatever the
    size, and levels of detail stay nearer (the old fixed (1 - r²)² disc of the whole diameter spread
    it wider: here +4 % at size 3, +27 % at size 6, +218 % with every column at level 2; now +10, +14
    and +36 % (+32 % while the octaves' a and c were fixed numbers, not the phase's), of which the ungated
    diffusion field's share at the coarse sprites' centres is 11 points: +21 % with ms_diffusion 0)."""
    x, y, z = np.meshgrid(*[(np.arange(k) + 0.5) / k for k in SHAPE], indexing="ij")
    density = np.clip(1.5 - 6.0 * ((x - 0.5) ** 2 + (y - 0.5) ** 2 * 0.3 + (z - 0.5) ** 2), 0, 1).astype(np.float32)
    sums = {}
    for march in (True, False):
        app = static_app(gpu, density, march=march, sigma_t=0.05)
        renderer = next(p for p in app.plugins if isinstance(p, (CloudRenderPlugin, RaymarchCloudsPlugin)))
        center = (np.array([8.0 + ORIGIN[0], 2.0, 8.0 + ORIGIN[2]]) * CELL) + [0, BASE, 0]
        aim(app, center + [100.0, 150.0, 700.0], center)
        for label, fields in ((("march",), {}),) if march else (
                ((3,), dict(size_factor=3.0)), ((6,), dict(size_factor=6.0)), (("lod",), dict(lod_pixels=1e4))):
            renderer.configure(**fields)
            image = app.read_linear()
            sums[label[0]] = float(image[..., :3].sum())
            assert 0.3 < image[..., 3].max() and image[..., 3].max() <= 1.0
        app.close()
    ref = sums["march"]
    # +10 % / +13.5 % here (+7 / +11 % under a fully sunlit ground): the footprint is the quadratic
    # B-spline's, a little wider than the march's hat (no grid ripple), on tall cells (30 m) that size 3
    # cuts at 2.5 sigma; the blob's shadow on the ground (G 0.37) widens the sky-ground difference,
    # which the sprites take once per sprite and the march per sample
    assert abs(sums[3] / ref - 1) < 0.11 and abs(sums[6] / ref - 1) < 0.15, sums
    assert abs(sums[6] / sums[3] - 1) < 0.05, sums
    assert abs(sums["lod"] / ref - 1) < 0.40, sums


def test_sprites_light_varies_across_each_sprite_as_the_sun_transmittance_does(gpu, ctx):
    """Toward a 20 deg sun a dense cumulus is bright only in its thin top, where T falls by e^1.75 per
    12 m cell: a sprite of one J across its footprint spread the top's light down over denser cells
    (and the body's dark up), so it came out darker than the reference march of the same volume and
    light (single scattering): image sum -13.7 %, rel. RMSE 19.6 %. With log T's slope across each
    sprite (sprite.vert v_slope): +4.4 % / 10.1 %; the march is the path tracer's order 1 (+1 %)."""
    from test_cloud_raymarch import lumpy_cumulus
    density, cell = lumpy_cumulus(), np.array([20.0, 12.0, 20.0])
    medium = CloudSettings(cell_size=tuple(cell), base_altitude=BASE, sigma_t=0.05, group_size=(8, 8),
                           smoothing_slices=1, sky_intensity=0.0, ground_albedo=0.0)
    single = dict(ms_contribution=0.0, ms_diffusion=0.0)
    sprites = CloudRenderPlugin(downsample=1, **single)
    march = RaymarchCloudsPlugin.reference(enabled=False, step=0.5, sun_steps=0, **single)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium, density=density), sprites, march)
    sun = Sun.from_angles(20.0, 90.0)
    sun.ambient = (0.0, 0.0, 0.0)
    app.insert_resource(sun)
    app.startup()
    lo = np.array([0.0, BASE, 0.0])
    centre, size = lo + np.array(density.shape) * cell / 2, float(np.max(np.array(density.shape) * cell))
    aim(app, centre + np.array([-1.7, -0.2, 0.0]) * 0.42 * size, centre)
    image = app.read_linear()[..., :3].astype(np.float64)
    sprites.configure(enabled=False)
    march.configure(enabled=True)
    ref = app.read_linear()[..., :3].astype(np.float64)
    app.close()
    mask = ref.sum(-1) > 1e-3 * ref.sum(-1).max()
    assert mask.mean() > 0.1, "the cloud fills much of the view"
    bias = image.sum() / ref.sum() - 1.0
    rmse = np.sqrt(((image - ref) ** 2).sum(-1)[mask].mean() / (ref ** 2).sum(-1)[mask].mean())
    assert abs(bias) < 0.08 and rmse < 0.14, (bias, rmse)


def test_sky_light_is_exact_in_a_white_furnace_and_follows_the_columns():
    """J's sky and ground part (atmos.plugins.clouds.light.medium, the numpy twin of volume.glsl's
    ambient_source, checked against the GPU by the sprite-vertex test): with sky and ground of equal
    radiance at albedo 1 every point of any cloud sees exactly that radiance (the old exp(-a tau)
    dimming gave less deep inside); sky only, the diffusion profile darkens from the top face to
    the bottom face, and a thin base seen from below gets the phase's forward share."""
    from atmos.plugins.clouds.sprites.plugin import CloudRenderSettings
    from atmos.plugins.clouds.light.medium import source_reference
    up, down = (v.ravel() for v in np.meshgrid([0.0, 0.3, 3.0, 30.0, 300.0], [0.0, 0.3, 3.0, 30.0, 300.0]))
    n = len(up)
    sky = np.array([0.3, 0.4, 0.6])
    furnace = CloudSettings(ground_albedo=1.0, sun_intensity=0.0)       # ground radiance = sky radiance
    j = source_reference(furnace, CloudRenderSettings(), np.ones(n), up, down, np.full(n, 0.3),
                         np.linspace(-1, 1, n), (1.0, 1.0, 1.0), sky, (0.0, 1.0, 0.0))
    np.testing.assert_allclose(j, np.broadcast_to(sky, j.shape), rtol=1e-12)
    dark = CloudSettings(ground_albedo=0.0, sun_intensity=0.0)
    def sky_part(tau_up, tau_down, ray_y=0.0):
        return source_reference(dark, CloudRenderSettings(), np.ones(1), [tau_up], [tau_down], [0.0], [ray_y],
                                (1.0, 1.0, 1.0), sky, (0.0, 1.0, 0.0))[0]
    top, middle, bottom = sky_part(0.0, 20.0), sky_part(10.0, 10.0), sky_part(20.0, 0.0)
    assert (top > middle).all() and (middle > bottom).all() and (bottom > 0).all()
    np.testing.assert_allclose(middle, 0.5 * sky)                      # deep inside: the faces' mean
    assert (sky_part(0.01, 0.0, 1.0) > 1.6 * sky_part(0.01, 0.0, 0.0)).all(), "thin base from below: forward share"
    assert np.isfinite(sky_part(1e30, 1e30)).all() and np.isfinite(sky_part(0.0, 0.0, 1.0)).all()


def test_sky_light_dies_with_depth_below_albedo_one(rng):
    """ambient_weights below albedo 1: each face's share solves the slab's diffusion equation w'' = kappa² w
    along the column (second differences on random columns), is 1 at its own extrapolated face and 0 at
    the other's, runs on continuously into the albedo-1 line, dies deep in a thick absorbing cloud, and
    stays finite at the extremes."""
    from atmos.plugins.clouds.light.medium import ambient_weights
    g, albedo = rng.uniform(0.5, 0.9), rng.uniform(0.8, 0.99)
    kappa = math.sqrt(3.0 * (1.0 - albedo) * (1.0 - albedo * g))
    z = 2.0 / (3.0 * (1.0 - albedo * g))
    total = rng.uniform(1.0, 60.0, 16)
    up = rng.uniform(0.1, 0.9, 16) * total
    h = 1e-3
    w = [ambient_weights(up + k * h, total - up - k * h, g, albedo, 0.0) for k in (-1, 0, 1)]
    second = (w[0] - 2.0 * w[1] + w[2]) / h ** 2
    np.testing.assert_allclose(second, kappa ** 2 * w[1], rtol=1e-4, atol=1e-9)
    face = ambient_weights(np.array([-z, total[0] + z]), np.array([total[0] + z, -z]), g, albedo, 0.0)
    np.testing.assert_allclose(face, [[1.0, 0.0], [0.0, 1.0]], atol=1e-12)
    near_one = ambient_weights(up, total - up, g, 1.0 - 1e-9, 0.0)
    np.testing.assert_allclose(near_one, ambient_weights(up, total - up, g, 1.0, 0.0), rtol=1e-6, atol=1e-9)
    deep = ambient_weights(60.0, 60.0, g, 0.9, 0.0)       # kappa >= 0.24 (g 0.9): e^(-kappa 60) < 1e-6
    assert deep.sum() < 1e-3 * ambient_weights(60.0, 60.0, g, 1.0, 0.0).sum(), deep
    for up_, down_ in ((0.0, 0.0), (1e30, 1e30), (0.0, 1e30), (1e-30, 0.0)):
        for a in (0.0, 0.5, 1.0):
            v = ambient_weights(up_, down_, g, a, 1.0)
            assert np.isfinite(v).all() and (v >= 0).all() and v.sum() <= 1.0 + 1e-12, (up_, down_, a, v)


def test_the_octaves_count_forward_scatterings_on_the_way_in(rng):
    """atmos.plugins.clouds.light.medium.octave_transmittances (the twin of shaders/lib/octaves.glsl, checked on the
    GPU through the renderers' J tests): light that reached a point forward-scattered k times, k Poisson
    with mean (1 - a) tau, against the Poisson probabilities written out; the last octave is every higher
    count, so the four sum to T^a; a lit rim (T -> 1) holds no multiple scattering, and any T in [0, 1]
    (0 and 1 included) gives finite values in [0, 1]."""
    import math

    from atmos.plugins.clouds.light.medium import octave_transmittances
    a = rng.uniform(0.05, 0.95)
    tau = np.concatenate([[0.0, 1e-6, 50.0, 1e4], rng.exponential(3.0, 200)])
    T = np.exp(-tau)
    P = octave_transmittances(T, a)
    x = (1.0 - a) * tau
    def poisson(k):         # T x^k / k!, in logs (x reaches ~10^4)
        with np.errstate(divide="ignore"):
            return np.exp(-tau) if k == 0 else np.exp(k * np.log(x) - math.lgamma(k + 1) - tau)
    for k in range(3):
        np.testing.assert_allclose(P[:, k], poisson(k), rtol=1e-9, atol=1e-300)
    higher = sum(poisson(k) for k in range(3, 400))          # the rest of the series (x <= 0.95 * 50 but the 1e4)
    np.testing.assert_allclose(P[:, 3], higher, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(P.sum(-1), T ** a, rtol=1e-9)
    assert np.all(np.isfinite(P)) and P.min() >= 0.0 and P.max() <= 1.0
    rim = octave_transmittances(np.array([1.0, 1.0 - 1e-9]), a)
    assert rim[:, 1:].max() < 1e-8 and rim[0, 0] == 1.0
    assert np.isfinite(octave_transmittances(np.array([0.0, 1e-300]), a)).all()


@pytest.mark.parametrize("g, g2, w, albedo", [(0.85, -0.3, 0.1, 1.0), (0.9, 0.0, 0.0, 0.95), (0.6, -0.3, 0.2, 0.9),
                                              (0.0, 0.0, 0.0, 1.0), (0.99, 0.0, 0.0, 1.0)])
def test_the_octaves_and_the_diffusion_field_follow_the_medium(g, g2, w, albedo):
    """medium.octave_parameters and field_weight, as light_uniforms hands them to both renderers: a and c
    from the phase (1 - a = g_mean, c = g) with albedo per forward scattering (a' = 1 - albedo (1 - a));
    the field's weight beta sqrt(a / a_0), exactly beta for the default phase (where it was fitted), less
    for a more forward phase, never below 0; set octaves win over the derived ones, and beta 0 stays 0."""
    from atmos.phase import Phase
    from atmos.plugins.clouds.light.medium import FIELD_REFERENCE_A, field_weight, octave_parameters
    from atmos.plugins.clouds.volume.light import DEFAULT_DIFFUSION, DEFAULT_OCTAVES, light_uniforms

    phase = Phase(g=g, g2=g2, w=w)
    settings = CloudSettings(phase=phase, albedo=albedo)
    g_mean = (1 - w) * g + w * g2
    a, b, c = octave_parameters(DEFAULT_OCTAVES, settings)
    assert a == pytest.approx(1.0 - albedo * g_mean, abs=1e-12) and b == DEFAULT_OCTAVES[1] and c == pytest.approx(g)
    values = light_uniforms(settings, Sun.from_angles(30.0, 0.0), DEFAULT_OCTAVES, DEFAULT_DIFFUSION)
    assert values["ms_octaves"] == (a, b, c)
    expected = DEFAULT_DIFFUSION * math.sqrt((1.0 - g_mean) / FIELD_REFERENCE_A)
    assert values["ms_diffusion"] == pytest.approx(expected, rel=1e-12) and math.isfinite(values["ms_diffusion"])
    if phase == Phase():
        assert values["ms_diffusion"] == DEFAULT_DIFFUSION
    assert FIELD_REFERENCE_A == pytest.approx(0.265)
    assert field_weight(0.0, DEFAULT_OCTAVES, settings) == 0.0
    assert field_weight(0.5, (0.4, 0.9, 0.5), settings) == pytest.approx(0.5 * math.sqrt(0.4 / FIELD_REFERENCE_A))
    assert octave_parameters((0.4, 0.9, 0.5), settings) == pytest.approx((1.0 - albedo * 0.6, 0.9, 0.5))
    forward = field_weight(DEFAULT_DIFFUSION, DEFAULT_OCTAVES, CloudSettings(phase=Phase(g=0.95, g2=0.0, w=0.0)))
    assert 0.0 <= forward < DEFAULT_DIFFUSION
