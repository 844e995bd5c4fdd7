"""Issue 15's ray-marched clouds: the march against its float64 reference, empty-space skipping and
early exit, extremes, culling, and the composition with fog, far field and terrain."""
import numpy as np
import pytest

from atmos import App, DefaultPlugins
from atmos.camera import Camera
from atmos.lighting import Sun
from atmos.phase import Phase
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.graph import RenderPass, TextureDesc, work_groups
from atmos.plugins.clouds.raymarch.plugin import LOW_COLOR, LOW_DEPTH, LOW_DISTANCE, sample_offset, skip_map
from atmos.render_core import DEPTH
from atmos.plugins.clouds.raymarch.reference import march_reference
from atmos.plugins.clouds.light.diffusion import DIFFUSION, read_field
from atmos.plugins.clouds.light.ground import ground_sun_of
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.clouds.raymarch.reference import integrate, rays
from atmos.plugins.clouds.light.medium import source_reference
from atmos.plugins.clouds.light.reference import multilinear

SHAPE = (16, 4, 16)
CELL = (20.0, 30.0, 25.0)
BASE = 400.0
CENTER = np.array([160.0, BASE + 60.0, 200.0])
DAY = Sun.from_angles(40.0, 70.0)


def volume():
    d = np.zeros(SHAPE, np.float32)
    d[3:9, 0:3, 5:12] = 1.0
    d[10:14, 1:4, 2:6] = 0.6
    d[12, 0, 12] = 2.0
    return d


def medium(**changes):
    return CloudSettings(cell_size=CELL, base_altitude=BASE, group_size=(4, 4), smoothing_slices=1,
                         sigma_t=changes.pop("sigma_t", 0.02), edge_fade=0.0, **changes)


def scene(gpu, density, sun=DAY, plugins=(), medium_fields=None, **fields):
    """``medium_fields``: CloudSettings changes (:func:`medium`)."""
    fields = dict(dict(resolution=1, jitter=False, detail_octaves=0), **fields)   # no noise unless asked
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium(**(medium_fields or {})), density=density),
                               RaymarchCloudsPlugin(**fields), *plugins)
    app.insert_resource(sun)
    app.startup()
    return app


def aim(app, position, target=CENTER):
    cam = app.resource(Camera)
    cam.position = np.array(position, float)
    cam.look_at(np.asarray(target, float))
    cam.near, cam.far = 1.0, 20000.0
    return cam


def linear(app):
    """The HDR frame in GL row order (row 0 at the bottom), like the reference."""
    return app.read_linear()[::-1].astype(np.float64)


# a sky that gives the sun's colour by altitude: the clouds take it at their heights (400..520 m here)
BY_ALTITUDE = Sun(DAY.direction, DAY.color, color_by_altitude=lambda d, h: np.stack(
    [h / 500.0, np.full_like(h, 0.6), np.full_like(h, 0.3)], -1))


def shading_volume(sim) -> np.ndarray:
    """Set A's shading volume (transmittance toward the sun) as float64 [x, y, z], read back."""
    texture = sim.a["transmittance"]
    nx, ny, nz = texture.size
    return np.frombuffer(texture.read(), np.float16).astype(np.float64).reshape(nz, ny, nx).transpose(2, 1, 0)


ABSORBING = dict(albedo=0.85, sigma_t=0.08, phase=Phase(0.7, -0.2, 0.15))    # sky light dies inside, kappa ~ 0.5


@pytest.mark.parametrize("sun, medium_fields", [(DAY, None), (BY_ALTITUDE, None), (DAY, ABSORBING)],
                         ids=["day", "by_altitude", "absorbing"])
def test_the_march_matches_its_float64_reference(gpu, ctx, sun, medium_fields):
    app = scene(gpu, volume(), sun, medium_fields=medium_fields, empty_space_skipping=False, min_transmittance=0.0,
                steps=96, step_growth=0.002)
    cam = aim(app, (80.0, 470.0, -150.0))
    image = linear(app)
    plugin = next(p for p in app.plugins if isinstance(p, CloudsPlugin))
    sim = plugin.simulation.sets()
    trans = shading_volume(sim)
    settings = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin)).settings
    ref = march_reference(volume(), trans, sim.settings, settings, sim.layout(), cam, sun, gpu.size,
                          field=read_field(sim.a[DIFFUSION]), ground_sun=ground_sun_of(sim))
    assert settings.ms_diffusion > 0 and read_field(sim.a[DIFFUSION])[..., 0].max() > 0.1, "the field must be in it"
    assert ref["alpha"].max() > 0.9 and (ref["alpha"] > 0.01).mean() > 0.05, "the view must see the clouds"
    light = ref["light"]
    rmse = np.sqrt(np.mean((image[..., :3] - light) ** 2)) / np.sqrt(np.mean(light ** 2))
    assert rmse < 0.005, f"colour off the reference: relative RMSE {rmse:.4f}"   # 4e-4 (the sun march's T: 1.2e-2 without)
    off = np.abs(image[..., 3] - ref["alpha"])
    assert np.percentile(off, 99.5) < 0.002, "coverage off the reference"
    assert (off > 0.02).mean() < 0.002, "only rays grazing the box's faces may differ (float32 entry/exit)"
    assert np.abs(image[..., 3] - ref["alpha"]).max() < 0.2
    app.close()


class LowProbe(RenderPass):
    """After the march: its low-res targets, the scene depth as a sampler reads it and the frame's sample
    offset, read back."""
    name = "raymarch_probe"
    phase = "translucent"

    def __init__(self, march):
        self.march, self.values = march, {}

    def setup(self, builder) -> None:
        for name in (LOW_COLOR, LOW_DISTANCE, LOW_DEPTH, DEPTH):
            builder.read(name)
        builder.create("probe_depth", TextureDesc(self.march.plugin.gpu.size, components=1, dtype="f4",
                                                  filter="nearest", storage=True), access="storage")
        builder.side_effect()

    def execute(self, frame) -> None:
        fetched = frame.image("probe_depth")
        frame.dispatch(frame.gpu.program(compute_shader="test/depth_fetch.comp"), work_groups(fetched.size, (8, 8)),
                       textures={"depth": DEPTH}, images={"fetched": "probe_depth"})
        for name, dtype, n in ((LOW_COLOR, np.float16, 4), (LOW_DISTANCE, np.float32, 2), (LOW_DEPTH, np.float32, 1),
                               ("probe_depth", np.float32, 1)):
            tex = frame.resource(name)
            self.values[name] = np.frombuffer(tex.read(), dtype).reshape(tex.size[1], tex.size[0], n).astype(np.float64)
        self.values["offset"] = sample_offset(self.march.frame_index - 1, 2)


def test_at_resolution_2_each_texel_holds_its_pixels_ray_and_the_exact_scene_depth(gpu, ctx):
    """The low-res targets (storage images) against the float64 reference at the pixels the frame's offset
    picks: colour and (a·distance, a) as at resolution 1, and the scene depth the ray saw, exactly."""
    from atmos.plugins.ground import GroundPlugin
    of_ground = GroundPlugin()
    app = scene(gpu, volume(), plugins=(of_ground,), resolution=2, empty_space_skipping=False,
                min_transmittance=0.0, steps=96, step_growth=0.002, reprojection=False)
    march = next(p for p in app.graph.passes if p.name == "cloud_raymarch")
    probe = app.graph.add_pass(LowProbe(march))
    cam = aim(app, (80.0, 470.0, -150.0))
    for _ in range(2):                      # two frames: two offsets
        app.render()
        v = probe.values
        w, h = gpu.size
        depth = v["probe_depth"][..., 0]
        assert (depth < 1.0).mean() > 0.2, "the view must see the ground"
        ox, oy = v["offset"]
        lh, lw = v[LOW_DEPTH].shape[:2]
        py, px = np.minimum(np.arange(lh) * 2 + oy, h - 1), np.minimum(np.arange(lw) * 2 + ox, w - 1)
        np.testing.assert_array_equal(v[LOW_DEPTH][..., 0], depth[np.ix_(py, px)])
        plugin = next(p for p in app.plugins if isinstance(p, CloudsPlugin))
        sim = plugin.simulation.sets()
        trans = shading_volume(sim)
        settings = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin)).settings
        _, start = rays(cam, gpu.size)
        scene_distance = np.where(depth < 1.0, cam.near / ((1.0 - depth) + depth * (cam.near / cam.far))
                                  * start / cam.near, np.inf)
        ref = march_reference(volume(), trans, sim.settings, settings, sim.layout(), cam, DAY, gpu.size,
                              scene=scene_distance, field=read_field(sim.a[DIFFUSION]),
                              albedo=of_ground.settings.albedo, ground_sun=ground_sun_of(sim))
        ref = {k: ref[k][np.ix_(py, px)] for k in ("light", "alpha", "distance")}
        assert ref["alpha"].max() > 0.9 and (ref["alpha"] > 0.01).mean() > 0.05, "the view must see the clouds"
        color, distance = v[LOW_COLOR], v[LOW_DISTANCE]
        rmse = np.sqrt(np.mean((color[..., :3] - ref["light"]) ** 2)) / np.sqrt(np.mean(ref["light"] ** 2))
        assert rmse < 0.005, f"colour off the reference: relative RMSE {rmse:.4f}"
        off = np.abs(color[..., 3] - ref["alpha"])
        assert np.percentile(off, 99.5) < 0.002 and off.max() < 0.2, "coverage off the reference"
        assert np.abs(distance[..., 1] - color[..., 3]).max() < 1e-3, "the distance's alpha is the colour's"
        d_rmse = np.sqrt(np.mean((distance[..., 0] - ref["distance"]) ** 2)) / np.sqrt(np.mean(ref["distance"] ** 2))
        assert d_rmse < 0.005, f"distance off the reference: relative RMSE {d_rmse:.4f}"
    app.close()


def lumpy_cumulus():
    """benchmarks/bench_cloud_light.py's cumulus: nine blobs, a flat base, on 20 x 12 x 20 m cells."""
    x, y, z = np.meshgrid(*[(np.arange(k) + 0.5) / k for k in (24, 16, 24)], indexing="ij")
    rng, d = np.random.default_rng(7), np.zeros_like(x)
    for _ in range(9):
        c, r = rng.uniform([0.3, 0.25, 0.3], [0.7, 0.55, 0.7]), rng.uniform(0.12, 0.22)
        d = np.maximum(d, 1.0 - ((x - c[0]) ** 2 + ((y - c[1]) * 1.3) ** 2 + (z - c[2]) ** 2) / r ** 2)
    return np.clip(d * np.clip((y - 0.1) / 0.1, 0.0, 1.0), 0.0, 1.0).astype(np.float32)


def rim_over_body(light, alpha):
    """Mean radiance of the pixels within 2 px of the cloud's silhouette (alpha > 0.01) over the rest's."""
    from numpy.lib.stride_tricks import sliding_window_view
    cover = alpha > 0.01
    body = sliding_window_view(np.pad(cover, 2), (5, 5)).all((-1, -2))
    lum = light.sum(-1)
    return lum[cover & ~body].mean() / lum[body].mean()


def test_toward_a_low_sun_the_rims_are_bright_against_a_dark_body(gpu, ctx):
    """A dense cumulus against a 5 deg sun, single scattering, against a float64 march with the exact sun
    transmittance (which the path tracer's order 1 matches: +0.8 % image sum at 192x128): the march's
    rim/body radiance ratio within 10 % of it (0.95x; the shading volume's trilinear T alone, i.e.
    sun_steps 0: 0.81x, a grey body with weak rims) and its relative RMSE under 15 % (10 %; 23 %)."""
    density, cell = lumpy_cumulus(), np.array([20.0, 12.0, 20.0])
    medium = CloudSettings(cell_size=tuple(cell), base_altitude=BASE, sigma_t=0.05, group_size=(8, 8),
                           smoothing_slices=1, sky_intensity=0.0, ground_albedo=0.0, edge_fade=0.0)
    march = RaymarchCloudsPlugin.reference(ms_contribution=0.0, step=0.5)
    sun = Sun.from_angles(5.0, 90.0)
    sun.ambient = (0.0, 0.0, 0.0)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium, density=density), march)
    app.insert_resource(sun)
    app.startup()
    lo = np.array([0.0, BASE, 0.0])
    hi = lo + np.array(density.shape) * cell
    centre, size = (lo + hi) / 2, float(np.max(hi - lo))
    cam = aim(app, centre + [-1.7 * size, -0.2 * size, 0.0], centre)
    image = linear(app)
    app.close()

    d, sun_dir = density.astype(np.float64), np.asarray(sun.direction, np.float64) / np.linalg.norm(sun.direction)
    h = 0.25 * cell.min()

    def exact_t(p):                        # the trilinear density marched toward the sun to the box's side
        tau = np.zeros(len(p))
        for k in range(int(np.linalg.norm(hi - lo) / h) + 1):
            q = (p + sun_dir * (k + 0.5) * h - lo) / (hi - lo)
            inside = np.all((q >= 0.0) & (q <= 1.0), axis=-1)
            if not inside.any():
                break
            tau += np.where(inside, multilinear(d, q * density.shape - 0.5), 0.0)
        return np.exp(-medium.sigma_t * h * tau)

    dirs, start = rays(cam, gpu.size)
    dirs, start = dirs.reshape(-1, 3), start.reshape(-1)
    pos = np.asarray(cam.position, np.float64)
    safe = np.where(np.abs(dirs) < 1e-12, 1e-12, dirs)
    t0, t1 = (lo - pos) / safe, (hi - pos) / safe
    color = np.asarray(sun.color, np.float64)
    zero = np.zeros(len(dirs))

    def sample(i, p):
        J = source_reference(medium, march.settings, exact_t(p), zero[i], zero[i], dirs[i] @ sun_dir, dirs[i][:, 1],
                             color, np.zeros(3), sun_dir)
        return multilinear(d, (p - lo) / (hi - lo) * density.shape - 0.5), J

    ref = integrate(pos, dirs, np.maximum(np.minimum(t0, t1).max(-1), start), np.maximum(t0, t1).min(-1),
                    march.settings.steps, march.settings.step * cell.min(), 0.0, 0.0, medium.sigma_t, sample,
                    (gpu.size[1], gpu.size[0]))
    exact, got = rim_over_body(ref["light"], ref["alpha"]), rim_over_body(image[..., :3], image[..., 3])
    assert exact > 1.5, f"the view must show a dark body with bright rims (exact rim/body {exact:.2f})"
    assert got > 0.9 * exact, f"rims too weak against the body: rim/body {got:.2f}, exact sun T {exact:.2f}"
    rmse = np.sqrt(np.mean((image[..., :3] - ref["light"]) ** 2) / np.mean(ref["light"] ** 2))
    assert rmse < 0.15, f"off the exact sun transmittance: relative RMSE {rmse:.3f}"


def test_the_skip_map_is_zero_only_where_the_trilinear_density_is(rng):
    d = np.zeros((24, 8, 20))
    d[rng.integers(0, 24, 6), rng.integers(0, 8, 6), rng.integers(0, 20, 6)] = 1.0
    group, band = (4, 4), 2
    grid = (6, 4, 5)
    maxima = np.zeros((1 + grid[1], grid[0], grid[2]))          # CloudSets' max maps, by hand
    for gx in range(grid[0]):
        for b in range(grid[1]):
            for gz in range(grid[2]):
                maxima[1 + b, gx, gz] = d[gx * 4:gx * 4 + 4, b * band:b * band + band, gz * 4:gz * 4 + 4].max()
    skip = skip_map(maxima)                                     # (gz, bands, gx)
    assert skip.shape == (grid[2], grid[1], grid[0]) and (skip == 0).any() and (skip > 0).any()
    points = rng.uniform(0, 1, (20000, 3)) * d.shape            # cells
    g = np.floor(points / (group[0], band, group[1])).astype(int)
    empty = skip[g[:, 2], g[:, 1], g[:, 0]] == 0
    assert empty.any()
    assert np.all(multilinear(d, points[empty] - 0.5) == 0.0), "density inside a skipped texel"


def test_empty_space_skipping_and_early_exit_change_the_image_by_little(gpu, ctx):
    app = scene(gpu, volume(), empty_space_skipping=False, min_transmittance=0.0)
    plugin = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    aim(app, (60.0, 520.0, -250.0))
    full = linear(app)
    plugin.configure(empty_space_skipping=True)
    skipped = linear(app)
    plugin.configure(min_transmittance=0.05)
    early = linear(app)
    scale = full[..., :3].max()
    assert scale > 0.1
    assert np.abs(skipped - full).max() < 0.02 * scale, "skipping moved the steps too much"
    assert np.abs(early[..., 3] - full[..., 3]).max() <= 0.051
    assert np.abs(early[..., :3] - full[..., :3]).max() < 0.06 * scale
    assert not np.array_equal(early, full), "the early exit must stop some rays"
    app.close()


@pytest.mark.parametrize("case", ["inside", "grazing", "zero", "full", "night"])
def test_extremes_stay_finite_and_sensible(gpu, ctx, case):
    density = {"zero": np.zeros(SHAPE, np.float32), "full": np.ones(SHAPE, np.float32),
               "inside": np.ones(SHAPE, np.float32)}.get(case, volume())
    sun = {"grazing": Sun.from_angles(0.3, 70.0), "night": Sun.from_angles(-30.0, 70.0, color=(0.0, 0.0, 0.0))}.get(case, DAY)
    # inside: a box full of cloud (the simulation's own shape; a cloud type would round its top off)
    app = scene(gpu, density, sun=sun, resolution=2, jitter=True, **({"cloud_type": None} if case == "inside" else {}))
    position = CENTER if case == "inside" else (80.0, 470.0, -150.0)
    aim(app, position, CENTER + (0.0, 0.0, 100.0) if case == "inside" else CENTER)
    frames = [linear(app) for _ in range(3)]
    for image in frames:
        assert np.isfinite(image).all() and image.min() >= 0.0
    alpha = frames[-1][..., 3]
    if case == "zero":
        assert alpha.max() == 0.0 and frames[-1][..., :3].max() == 0.0
    elif case in ("inside", "full"):
        assert alpha.min() > 0.9 if case == "inside" else alpha.max() > 0.9
        assert frames[-1][..., :3].mean() > 0.01, "lit, not black"
    elif case == "night":
        assert alpha.max() > 0.5
        day = scene(gpu, density, resolution=2, jitter=True)
        aim(day, position)
        assert frames[-1][..., :3].mean() < 0.5 * linear(day)[..., :3].mean(), "no sun: darker"
        day.close()
    else:
        assert alpha.max() > 0.5 and frames[-1][..., :3].max() > 0.01
    app.close()


def test_a_disabled_pass_is_culled_and_a_sprite_scene_has_none_of_it(gpu, ctx):
    app = scene(gpu, volume(), enabled=False, resolution=2)
    compiled = app.graph.compile()
    assert "cloud_raymarch" not in [p.name for p in compiled.order]
    assert LOW_COLOR not in compiled.resources
    plugin = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    plugin.configure(enabled=True)
    app.render()
    compiled = app.graph.compile()
    assert "cloud_raymarch" in [p.name for p in compiled.order] and LOW_COLOR in compiled.resources
    app.close()
    sprites = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium(), density=volume()),
                                   CloudRenderPlugin())
    sprites.startup()
    compiled = sprites.graph.compile()
    assert not any(p.name.startswith("cloud_raymarch") for p in compiled.order)
    assert not any(name.startswith("cloud_raymarch") for name in compiled.resources)
    sprites.close()


def test_a_scene_draws_with_one_cloud_renderer_never_both(gpu, ctx):
    from atmos.graph import GraphError
    both = r"'cloud_raymarch' and 'cloud_render' are alternatives \(exclusive group 'cloud volume'\)"
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium(), density=volume()),
                               CloudRenderPlugin(), RaymarchCloudsPlugin())
    with pytest.raises(GraphError, match=both):
        app.startup()                       # refused when the graph is first compiled
    app.close()
    sprites = CloudRenderPlugin(enabled=False)
    app = scene(gpu, volume(), plugins=(sprites,))
    march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    aim(app, (80.0, 470.0, -150.0))
    marched = linear(app)
    sprites.configure(enabled=True)         # turned on live beside the march: refused on the next frame
    with pytest.raises(GraphError, match=both):
        app.render()
    march.configure(enabled=False)          # the switch (either order between two frames)
    drawn = linear(app)
    assert [p.name for p in app.graph.compile().order if p.exclusive] == ["cloud_render"]
    sprites.configure(enabled=False)
    empty = linear(app)
    for image in (marched, drawn):          # each renderer alone draws the clouds
        assert (np.abs(image - empty)[..., :3].sum(-1) > 0.05).mean() > 0.05
    app.close()


def test_with_fog_far_field_and_terrain_the_clouds_show(gpu, ctx):
    from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
    from atmos.plugins.fog import FogPlugin
    from atmos.plugins.sky_gradient import SkyGradientPlugin
    from atmos.plugins.terrain import TerrainPlugin
    extra = (SkyGradientPlugin(), TerrainPlugin(), FogPlugin(density=0.002), CloudFarFieldPlugin(size=16))
    images = {}
    for clouds in (True, False):
        app = scene(gpu, volume(), plugins=extra, resolution=2, enabled=clouds)
        aim(app, (80.0, 470.0, -150.0))
        images[clouds] = app.read_linear()
        app.close()
    on, off = images[True], images[False]
    assert np.isfinite(on).all()
    changed = np.abs(on[..., :3] - off[..., :3]).sum(-1) > 0.02
    assert changed.mean() > 0.03, "the clouds must show over fog, far field and terrain"
    assert on[changed][..., :3].sum(-1).min() > 0.0, "not black"


def test_with_frozen_clouds_and_a_still_camera_the_detail_is_the_same_every_frame(gpu, ctx):
    app = scene(gpu, volume(), detail_octaves=3, wind=(0.0, 0.0, 0.0), empty_space_skipping=False)
    aim(app, (80.0, 470.0, -150.0))
    march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    first = linear(app)
    app.run_frames(3, 1 / 30)
    assert np.array_equal(linear(app), first), "no drift of the detail without wind (jitter off)"
    march.configure(detail_octaves=0)
    assert np.abs(linear(app)[..., 3] - first[..., 3]).mean() > 1e-3, "the detail must show"
    march.configure(detail_octaves=3, wind=(20.0, 0.0, 0.0))
    app.run_frames(3, 1 / 30)
    assert np.abs(linear(app)[..., 3] - first[..., 3]).mean() > 1e-4, "with wind the detail scrolls"
    app.close()


def test_detail_finer_than_a_pixel_fades_out_instead_of_aliasing(gpu, ctx):
    """From the same view the detail shows where its noise is many pixels wide, and is gone (the image
    of the smooth density) where a pixel spans a quarter of its tile (noise.py DETAIL_FADE): a far
    cloud keeps its shape instead of stripes and crawling jaggies."""
    app = scene(gpu, np.minimum(volume(), 1.0), detail_octaves=3, detail_scale=8.0, wind=(0.0, 0.0, 0.0))
    aim(app, CENTER + (-150.0, 60.0, -580.0))         # ~600 m: a pixel spans ~5 m
    march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    coarse = linear(app)
    march.configure(detail_octaves=0)
    smooth = linear(app)
    march.configure(detail_octaves=3, detail_scale=0.5)   # 10 m tiles: a pixel spans half of one
    fine = linear(app)
    app.close()
    assert smooth[..., 3].max() > 0.5, "the cloud is in view"
    assert np.abs(coarse[..., 3] - smooth[..., 3]).mean() > 1e-3, "8-cell billows show at this distance"
    assert np.abs(fine - smooth).max() < 1e-4, "noise finer than the pixel leaves the smooth density"


@pytest.mark.parametrize("resolution", [1, 2])
def test_a_still_camera_over_still_clouds_gives_a_still_picture_with_jitter_on(gpu, ctx, resolution):
    """The first-sample jitter is a pattern of the pixel, fixed in time: the resolve keeps each pixel's
    latest sample (no averaging), so an offset that moved per frame only made a still picture flicker."""
    app = scene(gpu, volume(), resolution=resolution, jitter=True, step=1.0, step_growth=0.0)
    aim(app, (80.0, 470.0, -150.0))
    frames = [linear(app) for _ in range(resolution ** 2 + 3)]
    app.close()
    plain = scene(gpu, volume(), resolution=resolution, jitter=False, step=1.0, step_growth=0.0)
    aim(plain, (80.0, 470.0, -150.0))
    midpoints = [linear(plain) for _ in range(resolution ** 2 + 1)][-1]
    plain.close()
    still = frames[-1]
    assert np.abs(still - midpoints).max() > 1e-3, "the jitter is in effect (coarse steps, other sample points)"
    change = max(np.abs(b - a).max() for a, b in zip(frames[resolution ** 2:], frames[resolution ** 2 + 1:]))
    assert change < 1e-6 * max(still[..., :3].max(), 1e-6), f"a still scene flickers: max |frame - previous| {change:.3g}"
