"""Issue 12, composition: clouds give the fog a distance of their own (atmos.composition), the fog
colour can follow the sky (aerial perspective), and a scene without fog allocates no distance target."""
import numpy as np
import pytest

from atmos import App, DefaultPlugins
from atmos.camera import Camera, view_basis
from atmos.composition import CLOUD_DISTANCE, ClearDistance, Composition
from atmos.graph import RenderPass
from atmos.lighting import Sun
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.fog import FogPlugin, FogSettings, apply_fog
from atmos.plugins.fog.factors import apply_fog_ref
from atmos.plugins.fog.sky_color import SAMPLES, horizon_at, horizon_table, sky_fog_color
from atmos.plugins.sky.light import horizon_colors
from atmos.plugins.sky import SkySettings
from atmos.plugins.clouds.weather import VolumeOrigin

SHAPE = (16, 4, 16)
CELL = (40.0, 40.0, 40.0)
BASE = 600.0


def unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def layers(rng, h=12, w=20):
    color = rng.uniform(0.0, 1.5, (h, w, 3)).astype(np.float32)
    distance = rng.uniform(0.0, 3000.0, (h, w)).astype(np.float32)
    distance[::3, ::4] = np.inf                                     # sky
    a = rng.uniform(0.0, 1.0, (h, w))
    a[1::4] = 0.0                                                   # no cloud
    a[2::5] = 1.0                                                   # opaque cloud
    dc = rng.uniform(50.0, 2500.0, (h, w))
    cloud = np.stack([a * dc, a], -1).astype(np.float32)
    dirs = unit(rng.normal(size=(h, w, 3))).astype(np.float32)
    positions = (dirs * np.where(np.isinf(distance), 1e4, distance)[..., None]).astype(np.float32)
    return color, distance, cloud, dirs, positions


@pytest.mark.parametrize("mode, sky, color_from, extra", [
    ("exp2", "keep", "fixed", {}),
    ("exp", "fog", "sky", {}),
    ("hetero_exp", "keep", "sky", dict(noise="procedural", tile_size=300.0)),
])
def test_apply_fog_fogs_a_cloud_layer_by_its_own_distance_like_the_float64_reference(gpu, ctx, rng, mode, sky,
                                                                                    color_from, extra):
    color, distance, cloud, dirs, positions = layers(rng)
    settings = FogSettings(mode=mode, density=6e-4, sky=sky, fog_color=(1.0, 0.9, 0.8), color_from=color_from,
                           **extra)
    horizon = horizon_colors(Sun.from_angles(5.0, 30.0), SkySettings(), SAMPLES) if color_from == "sky" else None
    got = apply_fog(gpu, color, distance, mode, 6e-4, (1.0, 0.9, 0.8), sky=sky, far=8000.0, cloud=cloud,
                    directions=dirs, positions=positions, horizon=horizon, color_from=color_from, **extra)
    want = apply_fog_ref(color, distance, settings, positions=positions, far=8000.0, cloud=cloud, directions=dirs,
                         horizon=horizon)
    assert np.abs(got - want).max() < 2e-4 * max(1.0, np.abs(want).max())
    plain = apply_fog_ref(color, distance, settings, positions=positions, far=8000.0, directions=dirs,
                          horizon=horizon)
    covered = cloud[..., 1] > 0.05
    assert np.abs(plain - want)[covered].max() > 0.05, "the cloud's own distance changes the fog"
    assert np.array_equal(plain[~(cloud[..., 1] > 0)], want[~(cloud[..., 1] > 0)])


def test_the_sky_fog_colour_is_the_horizon_sky_at_the_rays_angle_from_the_sun(rng):
    sun = Sun.from_angles(4.6, 80.0)
    s = sun.direction
    table = horizon_colors(sun, SkySettings(), SAMPLES)
    assert table.shape == (SAMPLES, 3) and np.isfinite(table).all()
    toward = sky_fog_color(unit([np.sin(np.radians(80)), 0.0, -np.cos(np.radians(80))]), table, (1, 1, 1), s)
    away = sky_fog_color(unit([-np.sin(np.radians(80)), 0.0, np.cos(np.radians(80))]), table, (1, 1, 1), s)
    assert toward.sum() > 2.0 * away.sum(), "the horizon glows toward the low sun"
    assert toward[0] > toward[2], "and is warm there"
    # on the horizon, a ray takes the sky in its own azimuth (the sky is symmetric about the sun's): a smooth
    # symmetric sky 1 + 0.5 cos(azimuth - the sun's), within the two tables' linear interpolation (< 0.01)
    sun_azimuth = np.arctan2(s[0], -s[2])
    smooth = np.repeat(1.0 + 0.5 * np.cos(2 * np.pi * np.arange(SAMPLES) / SAMPLES - sun_azimuth)[:, None], 3, 1)
    azimuths = rng.uniform(0.0, 2.0 * np.pi, 50)
    flat_rays = np.stack([np.sin(azimuths), np.zeros(50), -np.cos(azimuths)], -1)
    own = horizon_at(smooth, azimuths)
    assert np.abs(sky_fog_color(flat_rays, smooth, (1, 1, 1), s) - own).max() < 0.01
    # a ray down onto the ground under the low sun is far from it: no bright pillar under the sun
    down = sky_fog_color(unit([np.sin(np.radians(80)), -2.0, -np.cos(np.radians(80))]), table, (1, 1, 1), s)
    assert down.sum() < 0.8 * toward.sum(), "the ground under the sun is not fogged with the sun's glow"
    flat = horizon_table(Sun(ambient=(0.2, 0.3, 0.4)))          # no sky plugin: the Sun's ambient
    assert np.allclose(sky_fog_color(unit([1.0, 0.3, 2.0]), flat, (0.5, 1, 1), s), [0.1, 0.3, 0.4])
    with pytest.raises(ValueError, match="FogSettings.color_from"):
        FogSettings(color_from="sun")


class DistanceReadback(RenderPass):
    """Reads "cloud_distance" back (a reader in the App's Composition)."""
    name = "distance_readback"
    phase = "readback"
    value = None

    def setup(self, builder):
        builder.read(CLOUD_DISTANCE)
        builder.side_effect()

    def execute(self, frame):
        w, h = frame.gpu.size
        self.texture = frame.resource(CLOUD_DISTANCE)
        self.value = np.frombuffer(self.texture.read(), np.float32).reshape(h, w, 2)[::-1]


def cloud_app(gpu, downsample, fog=None):
    density = np.zeros(SHAPE, np.float32)
    density[4:12, 1:3, 4:12] = 1.0
    density[6:10, 0:4, 6:10] = 2.0
    settings = CloudSettings(cell_size=CELL, base_altitude=BASE, group_size=(8, 8), smoothing_slices=1, sigma_t=0.01)
    plugins = [DefaultPlugins(overlay=False), CloudsPlugin(settings, density=density),
               CloudRenderPlugin(downsample=downsample)]
    app = App(gpu).add_plugins(*plugins, *([fog] if fog else []))
    origin = app.resource(VolumeOrigin)
    origin.x, origin.z = 0.0, 0.0
    app.insert_resource(Sun.from_angles(40.0, 70.0))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([320.0, 150.0, 1400.0])
    cam.look_at(np.array([320.0, 680.0, 320.0]))                  # the clouds over the (empty) sky
    cam.near, cam.far = 1.0, 20000.0
    return app, cam


def test_a_cloud_scene_without_fog_allocates_no_distance_target(fresh_gpu):
    app, _ = cloud_app(fresh_gpu, 2)
    app.render()
    compiled = app.graph.compile()
    assert CLOUD_DISTANCE not in compiled.resources and "cloud_distance_low" not in compiled.resources
    assert not any(getattr(d, "components", None) == 2 for d in (r.desc for r in compiled.resources.values()))
    assert app.resource(Composition).writers == {"cloud_render"} and not app.resource(Composition).readers
    app.close()
    app, _ = cloud_app(fresh_gpu, 2, FogPlugin(mode="exp", density=1e-4, sky="keep"))
    app.render()
    compiled = app.graph.compile()
    assert compiled.resources[CLOUD_DISTANCE].creator == ClearDistance.name      # the shared clear
    assert compiled.resources[CLOUD_DISTANCE].readers == ["cloud_render", "fog"]   # the layer blends onto it
    app.close()
    app = App(fresh_gpu).add_plugins(DefaultPlugins(overlay=False), FogPlugin())     # fog without clouds
    app.startup()
    app.render()
    assert CLOUD_DISTANCE not in app.graph.compile().resources
    app.close()


@pytest.mark.parametrize("downsample", [1, 2])
def test_fog_attenuates_a_cloud_over_the_sky_by_the_clouds_own_distance(gpu, ctx, downsample):
    fog = FogPlugin(mode="exp", density=0.0, sky="keep", fog_color=(0.9, 0.6, 0.3))
    app, cam = cloud_app(gpu, downsample, fog)
    readback = app.graph.add_pass(DistanceReadback())
    app.resource(Composition).readers.add("distance_readback")
    app.run_frames(2)
    clear = app.read_linear()[..., :3].astype(np.float64)          # density 0: f = 1, the clouds unfogged
    cloud = readback.value.astype(np.float64)
    a = cloud[..., 1]
    assert a.max() > 0.9 and (a == 0).mean() > 0.2, "the view holds opaque clouds and open sky"
    dc = cloud[..., 0][a > 0.5] / a[a > 0.5]
    near = np.linalg.norm(cam.position - np.array([320.0, 680.0, 320.0]))
    assert 0.6 * near < np.median(dc) < 1.4 * near, "the distance is the clouds' own"
    fog.configure(density=8e-4)
    app.render()
    fogged = app.read_linear()[..., :3].astype(np.float64)
    w, h = gpu.size
    xs, ys = 2 * (np.arange(w) + 0.5) / w - 1, 1 - 2 * (np.arange(h) + 0.5) / h
    ndc = np.stack(np.broadcast_arrays(xs[None, :], ys[:, None], 1.0), -1)
    dirs = unit(ndc @ view_basis(cam, w / h).T)
    want = apply_fog_ref(clear, np.full((h, w), np.inf), fog.settings, cloud=cloud, directions=dirs,
                         camera=cam.position, ground=True)
    assert np.abs(fogged - want).max() < 4e-3 * max(1.0, want.max())      # the colour target is float16
    covered = a > 0.5
    assert np.abs(fogged - clear)[covered].mean() > 0.1, "clouds over the sky are fogged (not skipped as sky)"
    sky = (a == 0) & (dirs[..., 1] >= 0.0)          # below the horizon: the ground's continuation, fogged
    assert np.array_equal(fogged[sky], clear[sky]), "the open sky is kept"
    app.close()


def test_fog_attenuates_the_far_field_by_its_own_distance(gpu, ctx):
    from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
    fog = FogPlugin(mode="exp", density=0.0, sky="keep", fog_color=(0.9, 0.6, 0.3))
    density = np.zeros(SHAPE, np.float32)
    density[4:12, 1:3, 4:12] = 1.0
    settings = CloudSettings(cell_size=CELL, base_altitude=BASE, group_size=(8, 8), smoothing_slices=1, sigma_t=0.01,
                             edge_fade=0.4)                        # the far field fills what the volume fades out
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(settings, density=density),
                               CloudFarFieldPlugin(animate=False), fog)
    readback = app.graph.add_pass(DistanceReadback())
    app.resource(Composition).readers.add("distance_readback")
    origin = app.resource(VolumeOrigin)
    origin.x, origin.z = 0.0, 0.0
    app.insert_resource(Sun.from_angles(40.0, 70.0))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([320.0, 150.0, 1400.0])
    cam.look_at(np.array([320.0, 1400.0, 9000.0]))                # away from the volume: only the far field
    cam.near, cam.far = 1.0, 20000.0
    app.run_frames(2)
    # the far field is the first writer: it creates the distance and writes every pixel, no clear before
    assert app.graph.compile().resources[CLOUD_DISTANCE].creator == "cloud_far_field"
    w, h = gpu.size
    readback.texture.write(np.full((h, w, 2), np.nan, np.float32).tobytes())     # last frame's, pooled
    app.render()
    clear = app.read_linear()[..., :3].astype(np.float64)
    cloud = readback.value.astype(np.float64)
    a = cloud[..., 1]
    assert a.max() > 0.5 and (a == 0).mean() > 0.05, "the view holds far-field clouds and open sky"
    w, h = gpu.size
    xs, ys = 2 * (np.arange(w) + 0.5) / w - 1, 1 - 2 * (np.arange(h) + 0.5) / h
    ndc = np.stack(np.broadcast_arrays(xs[None, :], ys[:, None], 1.0), -1)
    dirs = unit(ndc @ view_basis(cam, w / h).T)
    layout = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation.sets().layout()
    plane = (0.5 * (layout.lo[1] + layout.hi[1]) - cam.position[1]) / dirs[..., 1]   # float64: the layer's hit
    seen = a > 0.05
    assert np.abs(cloud[..., 0][seen] / a[seen] / plane[seen] - 1.0).max() < 2e-3, "the far field's own distance"
    fog.configure(density=1e-4)
    app.render()
    fogged = app.read_linear()[..., :3].astype(np.float64)
    want = apply_fog_ref(clear, np.full((h, w), np.inf), fog.settings, cloud=cloud, directions=dirs,
                         camera=cam.position, ground=True)
    assert np.abs(fogged - want).max() < 4e-3 * max(1.0, want.max())      # the colour target is float16
    assert np.abs(fogged - clear)[a > 0.5].mean() > 0.05, "far-field clouds over the sky are fogged"
    sky = (a == 0) & (dirs[..., 1] >= 0.0)
    assert np.array_equal(fogged[sky], clear[sky]), "the open sky is kept"
    next(p for p in app.plugins if isinstance(p, CloudFarFieldPlugin)).configure(enabled=False)
    app.render()                                        # a far field that does not draw: the clear is back
    assert app.graph.compile().resources[CLOUD_DISTANCE].creator == ClearDistance.name
    assert np.array_equal(readback.value, np.zeros_like(readback.value))
    app.close()


def test_media_mix_reduces_to_each_medium_alone_and_never_counts_light_twice(rng):
    """atmos.composition.media_mix (the float64 twin of lib/media_mix.glsl): the other medium absent
    (T = 1, no light) gives each back; two media of one colour c are one medium, c (1 - T_a T_b);
    symmetric; an opaque medium's colour wins over a thin one's; thin media add."""
    from atmos.composition import media_mix
    n = 64
    t_a, t_b = rng.uniform(0.0, 1.0, n), rng.uniform(0.0, 1.0, n)
    c_a, c_b = rng.uniform(0.0, 2.0, (n, 3)), rng.uniform(0.0, 2.0, (n, 3))
    l_a, l_b = c_a * (1 - t_a)[:, None], c_b * (1 - t_b)[:, None]
    none = np.zeros((n, 3))
    assert np.allclose(media_mix(l_a, t_a, none, np.ones(n)), l_a) and np.allclose(media_mix(none, np.ones(n), l_b, t_b), l_b)
    same = media_mix(c_a * (1 - t_a)[:, None], t_a, c_a * (1 - t_b)[:, None], t_b)
    assert np.allclose(same, c_a * (1 - t_a * t_b)[:, None])
    assert np.allclose(media_mix(l_a, t_a, l_b, t_b), media_mix(l_b, t_b, l_a, t_a))
    opaque = media_mix(c_a * (1 - 1e-12), np.full(n, 1e-12), l_b * 1e-3, 1 - (1 - t_b) * 1e-3)
    assert np.allclose(opaque, c_a, rtol=1e-3, atol=1e-4)          # the thin one keeps tau_b / (tau_a + tau_b) < 4e-5
    thin = media_mix(c_a * 1e-6, np.full(n, 1 - 1e-6), c_b * 1e-6, np.full(n, 1 - 1e-6))
    assert np.allclose(thin, (c_a + c_b) * 1e-6, rtol=1e-5)
    assert np.isfinite(media_mix(l_a, np.zeros(n), l_b, np.zeros(n))).all()


def test_the_only_local_medium_that_covers_every_pixel_makes_the_media_targets():
    """Composition.media_first: the media targets are made by the one local medium that writes every
    pixel while it runs (no clear); with a second local medium, none reading them, or the first not
    running this frame, nobody makes them and media_clear clears them for blending."""
    from atmos.composition import Composition
    runs = {"fog": True}
    comp = Composition(media_writers={"fog"}, media_readers={"aerial_perspective"},
                       media_covers={"fog": lambda: runs["fog"]})
    assert comp.media and comp.media_first == "fog"
    runs["fog"] = False
    assert comp.media_first is None
    runs["fog"] = True
    comp.media_writers.add("volumetric_fog")
    assert comp.media_first is None, "two local media: both blend onto the cleared targets"
    comp.media_writers.discard("volumetric_fog")
    comp.media_readers.clear()
    assert not comp.media and comp.media_first is None
    comp.media_readers.add("aerial_perspective")
    comp.media_covers.clear()
    assert comp.media_first is None, "a medium that does not say it covers every pixel blends"


def test_the_first_covering_distance_writer_is_the_one_behind_else_the_only_one():
    """Composition.distance_first: of the writers that store every pixel while they run, the one drawn
    behind the others makes "cloud_distance"; else the only one that runs; two that are not behind, none
    running, or no reader: nobody, and the clear makes it."""
    runs = {"cloud_far_field": True, "cloud_raymarch": True}
    comp = Composition(writers={"cloud_far_field", "cloud_raymarch"}, readers={"fog"},
                       covers={name: (lambda name=name: runs[name]) for name in runs}, behind={"cloud_far_field"})
    assert comp.distance_first == "cloud_far_field" and not comp.distance_cleared
    runs["cloud_far_field"] = False
    assert comp.distance_first == "cloud_raymarch", "the far field off: the march is the only one"
    runs["cloud_raymarch"] = False
    assert comp.distance_first is None and comp.distance_cleared
    runs["cloud_raymarch"] = runs["cloud_far_field"] = True
    comp.behind.clear()
    assert comp.distance_first is None, "two covering writers, neither behind: both blend onto the clear"
    comp.behind.add("cloud_far_field")
    comp.readers.clear()
    assert comp.distance_first is None and not comp.distance_cleared, "nobody reads it: nothing is made"


@pytest.mark.parametrize("fields", [dict(resolution=1), dict(resolution=2), dict(resolution=2, reprojection=False)],
                         ids=["full", "temporal", "upsampled"])
def test_a_ray_march_makes_the_distance_itself_as_the_clear_and_blend_would(gpu, ctx, fields):
    """The ray march writes every pixel: with fog, it creates "cloud_distance" (no clear pass) and stores
    what blending onto the cleared target gave, colour and distance, bit for bit."""
    from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
    density = np.zeros(SHAPE, np.float32)
    density[4:12, 1:3, 4:12] = 1.0
    density[6:10, 0:4, 6:10] = 2.0
    results = []
    for cleared in (False, True):
        settings = CloudSettings(cell_size=CELL, base_altitude=BASE, group_size=(8, 8), smoothing_slices=1,
                                 sigma_t=0.01)
        fog = FogPlugin(mode="exp", density=4e-4, sky="keep", fog_color=(0.9, 0.6, 0.3))
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(settings, density=density),
                                   RaymarchCloudsPlugin(jitter=False, detail_octaves=0, **fields), fog)
        readback = app.graph.add_pass(DistanceReadback())
        comp = app.resource(Composition)
        comp.readers.add("distance_readback")
        origin = app.resource(VolumeOrigin)
        origin.x, origin.z = 0.0, 0.0
        app.insert_resource(Sun.from_angles(40.0, 70.0))
        app.startup()
        if cleared:
            comp.covers.pop("cloud_raymarch")            # as before: the clear, and the march blends onto it
        cam = app.resource(Camera)
        cam.position = np.array([320.0, 150.0, 1400.0])
        cam.look_at(np.array([320.0, 680.0, 320.0]))
        cam.near, cam.far = 1.0, 20000.0
        app.run_frames(3)
        w, h = gpu.size
        readback.texture.write(np.full((h, w, 2), np.nan, np.float32).tobytes())     # last frame's, pooled
        app.render()
        creator = app.graph.compile().resources[CLOUD_DISTANCE].creator
        assert creator == (ClearDistance.name if cleared else "cloud_raymarch")
        results.append((app.read_linear(), readback.value.copy()))
        app.close()
    (image, distance), (image_cleared, distance_cleared) = results
    a = distance[..., 1]
    assert np.isfinite(distance).all() and a.max() > 0.5 and (a == 0).mean() > 0.2, "clouds and open sky"
    assert np.array_equal(distance, distance_cleared) and np.array_equal(image, image_cleared)


@pytest.mark.parametrize("sky", ["sky", "sky_gradient"])
def test_a_sky_fills_the_colour_so_the_clear_leaves_it(gpu, ctx, monkeypatch, sky):
    """With a sky (which writes every pixel: the depth is all 1 before the geometry) the clear pass clears
    the depth alone; the frame is bit-identical to one whose colour was cleared too. Without a sky the
    colour is cleared."""
    import moderngl

    from atmos.plugins.ground import GroundPlugin
    from atmos.plugins.sky import SkyPlugin
    from atmos.plugins.sky_gradient import SkyGradientPlugin
    cleared = []
    clear = moderngl.Framebuffer.clear

    def spy(self, *args, **kwargs):
        cleared.append(len(self.color_attachments))
        return clear(self, *args, **kwargs)

    monkeypatch.setattr(moderngl.Framebuffer, "clear", spy)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyPlugin() if sky == "sky" else SkyGradientPlugin(),
                               GroundPlugin())
    app.startup()
    cam = app.resource(Camera)
    cam.position, cam.pitch = np.array([0.0, 30.0, 0.0]), 0.1
    comp = app.resource(Composition)
    assert comp.backgrounds == {sky}
    cleared.clear()
    app.update(1 / 60)
    kept = gpu.read_pixels()
    assert cleared == [0], "the depth alone"
    comp.backgrounds.clear()
    cleared.clear()
    app.update(0.0)
    assert cleared == [1], "colour and depth"
    np.testing.assert_array_equal(gpu.read_pixels(), kept)
    app.close()
