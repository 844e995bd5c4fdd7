"""The ray march's volumetric far field (issues 15 and 12): the march beyond the volume against its
float64 reference, the 2D far-field pass culled while the march draws the far field, and extremes."""
import numpy as np
import pytest

from atmos import App, DefaultPlugins
from atmos.camera import Camera
from atmos.lighting import Sun
from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
from atmos.plugins.clouds.far_field.cover import level_table
from atmos.plugins.clouds.far_field.layer import drift
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.raymarch.far_reference import FarField, far_march_reference
from atmos.plugins.clouds.light.ground import ground_sun_of
from atmos.plugins.clouds import CloudSettings, CloudsPlugin

SHAPE = (16, 8, 16)
CELL = (40.0, 40.0, 40.0)
BASE = 400.0
DAY = Sun.from_angles(35.0, 70.0)
# a sun whose colour changes over the band (400..720 m): the far clouds take it at their heights
BY_ALTITUDE = Sun(DAY.direction, DAY.color, color_by_altitude=lambda d, h: np.stack(
    [np.ones_like(h), (h - 300.0) / 500.0, ((h - 300.0) / 420.0) ** 2], -1))
FAR = dict(size=64, tile_size=20000.0, base_frequency=4, animate=False)   # mip 0 out to far_distance


PROFILE = np.array([0.1, 0.5, 1.0, 1.0, 0.8, 0.5, 0.25, 0.0], np.float32)   # a cloud's density by height


def columns():
    """Half the columns full, a base and a fading top (PROFILE): the far field's measured cover about a
    half, its vertical profile that shape."""
    d = np.zeros(SHAPE, np.float32)
    x, z = np.meshgrid(np.arange(SHAPE[0]), np.arange(SHAPE[2]), indexing="ij")
    d.transpose(0, 2, 1)[((x // 4 + z // 4) % 2 == 0)] = PROFILE
    return d


def scene(gpu, sun=DAY, far=True, **fields):
    fields = dict(dict(resolution=1, jitter=False, detail_octaves=0, min_transmittance=0.0, far_distance=8000.0,
                       far_step_growth=0.01), **fields)
    medium = CloudSettings(cell_size=CELL, base_altitude=BASE, group_size=(4, 4), smoothing_slices=1, sigma_t=0.02,
                           edge_fade=0.2)
    plugins = [DefaultPlugins(overlay=False), CloudsPlugin(medium, density=columns()), RaymarchCloudsPlugin(**fields)]
    if far:
        plugins.append(CloudFarFieldPlugin(**FAR))
    app = App(gpu).add_plugins(*plugins)
    app.insert_resource(sun)
    app.startup()
    return app


def aim(app, position, yaw=0.0, pitch=0.0):
    cam = app.resource(Camera)
    cam.position = np.array(position, float)
    cam.yaw, cam.pitch = yaw, pitch
    cam.near, cam.far = 1.0, 20000.0
    return cam


def of(app, kind):
    return next(p for p in app.plugins if isinstance(p, kind))


def field_reference(app) -> FarField:
    """The far field's columns at mip 0 in float64, from the GPU's textures and measured column quantiles."""
    far = of(app, CloudFarFieldPlugin)
    layer, params = far.layer, far.settings
    sim = of(app, CloudsPlugin).simulation.sets()
    quantiles = level_table(params.base_frequency, params.seed, params.size)[0][0]
    _, columns = layer.read_cover()
    return FarField(octaves=[layer.octaves.download(k) for k in range(4)], offsets=drift(params, sim, 0.0, layer.tile_size),
                    tile_size=layer.tile_size, quantiles=quantiles, columns=columns, profile=layer.read_profile(),
                    sun_profile=layer.light.read()["sun_profile"], field_profile=layer.light.read().get("field_profile"))


@pytest.mark.parametrize("yaw, fields, sun", [(-np.pi / 2, {}, DAY), (0.0, dict(ms_diffusion=2.0), DAY),
                                               (-np.pi / 2, {}, BY_ALTITUDE)], ids=["day", "field", "by_altitude"])
def test_the_far_field_march_matches_its_float64_reference(gpu, ctx, yaw, fields, sun):
    """Outside the volume, above it, looking away from it. Yaw 0 looks across the sun, where the far
    field's light from the volume's diffusion field by rank (RankLight) is half the image: the reference
    without it is far off (the test can fail). A sun whose colour changes with height: each sample takes
    its own."""
    app = scene(gpu, sun, steps=256, **fields)
    cam = aim(app, (-2500.0, BASE + 900.0, 200.0), yaw=yaw, pitch=-0.3)
    image = app.read_linear()[::-1].astype(np.float64)
    shape = of(app, CloudFarFieldPlugin).layer.read_profile()[-1, :, 0]
    assert np.allclose(shape, PROFILE / PROFILE.sum(), atol=1e-3), "the far field's profile is the volume's"
    sim = of(app, CloudsPlugin).simulation.sets()
    layout = sim.layout()
    band = (float(layout.lo[1]), float(layout.hi[1] - layout.lo[1]))
    ground_sun = ground_sun_of(sim)
    ref = far_march_reference(field_reference(app), sim.settings, of(app, RaymarchCloudsPlugin).settings, band,
                              cam, sun, gpu.size, ground_sun=ground_sun)
    alpha = ref["alpha"]
    assert 0.05 < (alpha > 0.05).mean() < 0.95 and alpha.max() > 0.5, "the view must see far clouds and gaps"
    light = ref["light"]
    rmse = np.sqrt(np.mean((image[..., :3] - light) ** 2)) / np.sqrt(np.mean(light ** 2))
    assert rmse < 0.03, f"colour off the reference: relative RMSE {rmse:.4f}"
    off = np.abs(image[..., 3] - alpha)
    assert np.percentile(off, 99) < 0.01 and off.mean() < 0.003, f"coverage off the reference: {off.max():.4f}"
    if fields:
        far = field_reference(app)
        assert far.field_profile is not None, "the sets carry a diffusion field"
        far.field_profile = None
        without = far_march_reference(far, sim.settings, of(app, RaymarchCloudsPlugin).settings, band, cam, DAY,
                                      gpu.size, ground_sun=ground_sun)["light"]
        assert np.sqrt(np.mean((image[..., :3] - without) ** 2)) / np.sqrt(np.mean(without ** 2)) > 0.3
    app.close()


@pytest.mark.parametrize("far_first", [False, True])
def test_the_2d_pass_is_culled_while_the_march_draws_the_far_field(gpu, ctx, far_first):
    """In either plugin order (they meet in FarFieldLink), and again as soon as the march stops."""
    if far_first:
        medium = CloudSettings(cell_size=CELL, base_altitude=BASE, group_size=(4, 4), smoothing_slices=1,
                               edge_fade=0.2)
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudFarFieldPlugin(**FAR),
                                   CloudsPlugin(medium, density=columns()), RaymarchCloudsPlugin(resolution=1))
        app.startup()
    else:
        app = scene(gpu)
    names = lambda: [p.name for p in app.graph.compile().order]
    app.render()
    assert "cloud_far_field" not in names() and "cloud_raymarch" in names()
    march, far = of(app, RaymarchCloudsPlugin), of(app, CloudFarFieldPlugin)
    far.configure(enabled=False)
    app.render()
    assert not march.marches_far_field() and "cloud_far_field" not in names(), "no far field: none marched"
    far.configure(enabled=True)
    for change in (dict(far_field=False), dict(far_field=True, enabled=False)):
        march.configure(**change)
        app.render()
        assert "cloud_far_field" in names(), f"the 2D far field draws again with {change}"
    app.close()


def test_the_march_continues_the_clouds_past_the_volume(gpu, ctx):
    """From above, looking out past the volume: with the far field the march's clouds go on."""
    images = {}
    for far in (False, True):
        app = scene(gpu, far=far, far_distance=20000.0, resolution=2, jitter=True)
        aim(app, (320.0, 2000.0, 320.0), pitch=-0.15)           # the view meets the layer ~8 km out
        images[far] = app.read_linear()
        app.close()
    h = images[True].shape[0]
    band = slice(h // 3, 2 * h // 3)                     # around the horizon
    assert images[False][band, :, 3].mean() < 0.5 * images[True][band, :, 3].mean()


@pytest.mark.parametrize("case", ["above_10km", "below", "grazing", "night"])
def test_far_field_extremes_stay_finite_and_sensible(gpu, ctx, case):
    sun = Sun.from_angles(-20.0, 70.0, color=(0.0, 0.0, 0.0)) if case == "night" else DAY
    if case == "night":
        sun.ambient = (0.0, 0.0, 0.0)
    app = scene(gpu, sun=sun, resolution=2, jitter=True, detail_octaves=3, far_distance=60000.0,
                far_step_growth=0.02)
    position, pitch = {"above_10km": ((160.0, 10000.0, 320.0), -0.6), "below": ((160.0, 50.0, 320.0), 0.15),
                       "grazing": ((160.0, BASE + 160.0, 320.0), 0.0), "night": ((160.0, 50.0, 320.0), 0.15)}[case]
    aim(app, position, pitch=pitch)
    frames = [app.read_linear() for _ in range(3)]
    for image in frames:
        assert np.isfinite(image).all() and image.min() >= 0.0 and image[..., 3].max() <= 1.0 + 1e-3
    alpha, rgb = frames[-1][..., 3], frames[-1][..., :3]
    assert alpha.max() > 0.3, "far clouds in view"
    if case == "night":
        assert rgb.max() < 0.05 * alpha.max() + 1e-3, "no sun, no sky: dark"
    else:
        assert rgb[alpha > 0.3].mean() > 0.05, "lit, not black"
    app.close()


def test_the_far_field_alone_is_the_marchs_far_field_drawn_behind_the_sprites(gpu, ctx):
    """``volume=False``: the march draws only the far field (the same samples where the rays miss the
    volume), before the sprites and not their alternative; the 2D pass steps aside, the march makes the
    fog's distance, publishes no cloud type; without a far field it is culled."""
    from atmos.graph import GraphError
    from atmos.plugins.clouds.sprites import CloudRenderPlugin
    from atmos.plugins.fog import FogPlugin
    from atmos.composition import CLOUD_DISTANCE
    from atmos.plugins.clouds.volume.shape import DrawnShape
    app = scene(gpu, steps=256, cloud_type=None)    # untyped: the shadows on the ground alike either way
    aim(app, (-2500.0, BASE + 900.0, 200.0), yaw=-np.pi / 2, pitch=-0.3)     # away from the volume
    whole = app.read_linear()
    march = of(app, RaymarchCloudsPlugin)
    march.configure(volume=False)
    alone = app.read_linear()
    assert (alone[..., 3] > 0.05).mean() > 0.05, "far clouds in view"
    assert np.array_equal(alone, whole), "the rays never meet the volume: the same far field"
    app.close()

    medium = CloudSettings(cell_size=CELL, base_altitude=BASE, group_size=(4, 4), smoothing_slices=1, sigma_t=0.02,
                           edge_fade=0.2)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(medium, density=columns()),
                               CloudRenderPlugin(), RaymarchCloudsPlugin(volume=False, cloud_type=1.0),
                               CloudFarFieldPlugin(**FAR), FogPlugin(mode="exp", density=1e-4, sky="keep"))
    app.insert_resource(DAY)
    app.startup()
    aim(app, (-600.0, BASE + 200.0, 320.0), yaw=np.pi / 2, pitch=0.05)        # the volume and the far field beyond
    image = app.read_linear()
    compiled = app.graph.compile()
    order = [p.name for p in compiled.order]
    assert "cloud_far_field" not in order and order.index("cloud_raymarch") < order.index("cloud_render")
    assert compiled.resources[CLOUD_DISTANCE].creator == "cloud_raymarch"
    assert app.resource(DrawnShape).source is None or app.resource(DrawnShape).source() is None, \
        "the sprites draw the volume: no type for its shadows"
    assert np.isfinite(image).all() and (image[..., 3] > 0.05).mean() > 0.05
    march = of(app, RaymarchCloudsPlugin)
    of(app, CloudRenderPlugin).configure(ms_diffusion=1.0)      # the field's heavier reader ...
    assert of(app, CloudFarFieldPlugin).light_settings() is march.settings, "... but the march lights its far field"
    march.configure(volume=True)                                 # beside the sprites: refused
    with pytest.raises(GraphError, match="exclusive group 'cloud volume'"):
        app.render()
    march.configure(volume=False)
    of(app, CloudFarFieldPlugin).configure(enabled=False)
    app.render()
    assert "cloud_raymarch" not in [p.name for p in app.graph.compile().order], "nothing to march: culled"
    app.close()
