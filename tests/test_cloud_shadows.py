"""Cloud ground shadows (thesis 7.3.1): GPU against the float64 reference, extremes, and a look at them."""
import math
import os

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.graph import PassBuilder, RenderPass
from atmos.lighting import Sun
from atmos.plugin import Plugin
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.shadows import CloudShadowSettings, CloudShadowsPlugin, cloud_layout, reference
from atmos.plugins.clouds import CloudSettings, CloudSimulation, CloudsPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.clouds.weather import VolumeOrigin, WeatherSettings
from atmos.render_core import COLOR, DEPTH, CapturePass

OUT = os.path.join(os.path.dirname(__file__), "..", "out")


# -- helpers shared with test_light_shafts (CapturePass reads the colour back) --------------------------------------------------------
class FillPass(RenderPass):
    """Writes given arrays (GL row order: row 0 at the bottom) into "color" (h, w, 4) and "depth" (h, w)."""
    name = "test_fill"
    phase = "opaque"

    def __init__(self):
        self.color = self.depth = None

    def setup(self, builder: PassBuilder) -> None:
        builder.write(COLOR)
        builder.write(DEPTH)

    def execute(self, frame) -> None:
        if self.color is not None:
            frame.resource(COLOR).write(np.ascontiguousarray(self.color, np.float16).tobytes())
        if self.depth is not None:
            frame.resource(DEPTH).write(np.ascontiguousarray(self.depth, np.float32).tobytes())


class _PassPlugin(Plugin):
    def __init__(self, p: RenderPass):
        self.p = p

    def build(self, app) -> None:
        app.graph.add_pass(self.p)


def pass_plugin(p: RenderPass) -> Plugin:
    """A plugin (of a type of its own: an App takes each plugin type once) that adds the pass ``p``."""
    return type(f"Plugin_{p.name}", (_PassPlugin,), {})(p)


def world_points(camera: Camera, size, depth: np.ndarray) -> np.ndarray:
    """float64 world positions behind each pixel (GL row order) of a depth buffer."""
    w, h = size
    x, y = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    ndc = np.stack([2 * x - 1, 2 * y - 1, 2 * depth - 1, np.ones_like(x)], axis=-1)
    hit = ndc @ np.linalg.inv(camera.view_projection(w / h)).T
    return hit[..., :3] / hit[..., 3:]


def depth_of(camera: Camera, size, points: np.ndarray) -> np.ndarray:
    clip = np.concatenate([points, np.ones(points.shape[:-1] + (1,))], -1) @ camera.view_projection(size[0] / size[1]).T
    return 0.5 * clip[..., 2] / clip[..., 3] + 0.5


def ray_dirs(camera: Camera, size) -> np.ndarray:
    far = world_points(camera, size, np.ones(size[::-1]))
    d = far - camera.position
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def save_png(name: str, pixels: np.ndarray) -> str:
    from PIL import Image
    os.makedirs(OUT, exist_ok=True)
    path = os.path.abspath(os.path.join(OUT, name))
    Image.fromarray(pixels).save(path)
    return path


# -- the scene --------------------------------------------------------------------------------
def weather(shape=(16, 8, 16), **kw):
    base = dict(volume_shape=shape, cloud_density=12, density_adaption=4, cloud_size=4.0, cloud_size_variance=1.5,
                region_margin=6.0, lifetime=60.0, lifetime_variance=10.0, hum_scale=0.2, act_scale=0.01,
                ext_scale=0.1, altitude=0.5, altitude_variance=0.1, vertical_scale=0.5, wind=(0.5, 0.0, 0.25))
    base.update(kw)
    return WeatherSettings(**base)


def shadow_app(gpu, params: CloudShadowSettings, wp=None, cell_size=(1.0, 1.0, 1.0), warmup=0, scene=False,
               origin=(0.0, 0.0)):
    """Clouds (volume at ``origin`` x, z cells), then (scene) sky + ground or (else) the fill pass,
    then the shadows, then the probe."""
    fill, probe = FillPass(), CapturePass()
    settings = CloudSettings(smoothing_slices=2, group_size=(8, 8), shading=False, cell_size=cell_size)
    drawn = [SkyGradientPlugin(), GroundPlugin()] if scene else [pass_plugin(fill)]
    app = App(gpu).insert_resource(VolumeOrigin(origin[0], 0.0, origin[1]))
    app.add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(settings, weather=wp or weather(), seed=5,
                                                                           warmup_steps=warmup),
                               *drawn, CloudShadowsPlugin(params), pass_plugin(probe))
    app.startup()
    return app, app.resource(CloudSimulation), fill, probe


def draw_typed(app, sim, rng, kind):
    """Have the scene's clouds drawn with a cloud type, as a ray march with one would publish it
    (:class:`~atmos.plugins.clouds.volume.shape.DrawnShape`): ``kind`` None (as simulated), "type" (one
    random type) or "map" (a random CloudTypeMap over the volume's footprint, its texture made here).
    Returns the float64 twins' keywords (cloud_type, type_map)."""
    import moderngl
    from atmos.plugins.clouds.volume.shape import CloudTypeMap, drawn_shape
    shape = drawn_shape(app)
    if kind is None:
        shape.source = None
        return {"cloud_type": None, "type_map": None}
    if kind == "type":
        t = float(rng.uniform(0.0, 1.0))
        shape.source = lambda: (t, None, None)
        return {"cloud_type": t, "type_map": None}
    layout = sim.sets().layout()
    size = (layout.hi - layout.lo)[[0, 2]]
    type_map = CloudTypeMap(rng.uniform(0.0, 1.0, (5, 7)), tuple(layout.lo[[0, 2]] + 0.1 * size), tuple(0.8 * size))
    tex = app.gpu.ctx.texture((7, 5), 1, type_map.types.tobytes(), dtype="f4")
    tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
    tex.repeat_x = tex.repeat_y = False
    shape.source = lambda: (None, type_map, tex)
    return {"cloud_type": None, "type_map": type_map}


def write_sums(sim, texture_set, sums: np.ndarray) -> None:
    """Overwrite a set's top-view maps with ``sums`` (layers, nx, nz): its contents are new (``version``)."""
    sim.maps_of(texture_set).sums.write(np.ascontiguousarray(sums.transpose(0, 2, 1), np.float32).tobytes())
    texture_set.version += 1


def test_gpu_matches_reference_on_random_scenes(gpu, ctx, rng):
    size = gpu.size
    cell = tuple(rng.uniform([3.0, 1.0, 3.0], [8.0, 3.0, 8.0]))
    params = CloudShadowSettings(base_altitude=rng.uniform(20, 80), cell_size=cell, sigma=rng.uniform(0.2, 1.0),
                               strength=rng.uniform(0.5, 2.0), direct_fraction=rng.uniform(0.5, 1.0))
    app, sim, fill, probe = shadow_app(gpu, params)
    for _ in range(2):
        app.update(1 / 30)                      # the next step under way: 0 < t < 1
    a, b, t = sim.view()
    assert 0 < t < 1
    nx, ny, nz = sim.shape
    layers = 1 + sim.maps_of(a).bands
    sums = [rng.uniform(0, ny, (layers, nx, nz)) for _ in range(2)]
    write_sums(sim, a, sums[0])
    write_sums(sim, b, sums[1])
    # each set drawn where it was computed: B at its placement, A at another (sampled through a_shift)
    place_b = (float(rng.integers(-12, -4)), 0.0, float(rng.integers(-12, -4)))
    place_a = (place_b[0] - float(rng.integers(1, 4)), 0.0, place_b[2] + float(rng.integers(1, 4)))
    sim._placement[id(a)], sim._placement[id(b)] = place_a, place_b
    sets = sim.sets()
    assert sets.a_shift[0] > 0 and sets.a_shift[2] < 0
    sun = Sun.from_angles(rng.uniform(20, 85), rng.uniform(0, 360), color=tuple(rng.uniform(0.2, 2, 3)))
    app.insert_resource(sun)
    layout = cloud_layout(sets, params)
    centre = (np.array([place_b[0], 0.0, place_b[2]]) + np.array([nx, 0.0, nz]) / 2) * cell
    centre[1] = (layout.lo[1] + layout.hi[1]) / 2
    shadow = centre - sun.direction * centre[1] / sun.direction[1]      # where the layer's shadow falls
    cam = app.resource(Camera)
    cam.near, cam.far = 1.0, 1000.0          # float32 depth keeps points to ~1 cm
    cam.position = shadow + np.array([rng.uniform(-60, 60), rng.uniform(30, 250), rng.uniform(-60, 60)])
    cam.look_at(shadow + np.array([rng.uniform(-20, 20), 0.0, rng.uniform(-20, 20)]))
    h, w = size[1], size[0]
    rays = ray_dirs(cam, size)
    to_ground = np.where(rays[..., 1] < 0, cam.position[1] / np.maximum(-rays[..., 1], 1e-9), np.inf)
    along = np.where(rng.random((h, w)) < 0.8, rng.uniform(0.9, 1.0, (h, w)), rng.uniform(0.2, 1.0, (h, w)))
    points = cam.position + rays * (np.minimum(to_ground, 300.0) * along)[..., None]
    depth = depth_of(cam, size, points)
    depth[rng.random((h, w)) < 0.1] = 1.0       # sky pixels stay as they are
    color = rng.uniform(0.5, 2.0, (h, w, 4))
    fill.color, fill.depth = color, depth
    app.render()                  # render only: the sets stay as written
    assert np.isfinite(probe.color).all()
    weight = reference.direct_weight(sun.direction, sun.color, params)
    expected = reference.shadow_factor(world_points(cam, size, probe.depth), sums[0][0], sums[1][0], t,
                                       sun.direction, weight, params.sigma * params.strength, layout,
                                       sets.a_shift)
    expected[probe.depth >= 1.0] = 1.0
    before = color.astype(np.float16).astype(np.float64)
    error = np.abs(probe.color[..., :3] / before[..., :3] - expected[..., None]).max(-1)
    # 2^-11: the f2 colour; a few far pixels lose more to float32 depth reconstruction on random,
    # texel-rough maps (a half-texel or A/B mix-up would move most pixels far beyond both bounds)
    assert np.quantile(error, 0.995) < 2e-3 and error.max() < 1e-2, f"max error {error.max()}"
    assert np.array_equal(probe.color[..., 3], before[..., 3])
    print(f"shadowed pixels {(expected < 0.95).mean():.2f}, max error {error.max():.2e}")
    assert (expected < 0.95).sum() > 500, "the random scene has shadows to compare"
    app.close()


def test_reference_projects_along_the_sun_onto_the_layer():
    layout = CloudLayout(shape=(4, 2, 4), cell=(10.0, 5.0, 10.0), origin_xz=(-2.0, -2.0), base=100.0, group=(2, 2))
    sums = np.zeros((4, 4))
    sums[3, 1] = 2.0                                    # cell centre x = (-2 + 3.5)·10 = 15, z = -5
    s = np.array([-1.0, 1.0, 0.0]) / math.sqrt(2)       # 45°, toward -x: mid plane at 105 m
    f = reference.shadow_factor(np.array([[120.0, 0.0, -5.0], [15.0, 0.0, -5.0], [16.0, 104.0, -5.0],
                                          [120.0, 110.0, -5.0]]), sums, sums, 0.0, s, 1.0, 0.5, layout)
    assert f[0] == pytest.approx(math.exp(-1.0))       # ground point 105 m east of the cloud
    assert f[1] == 1.0                                  # right below it: the shadow falls elsewhere
    assert f[2] == pytest.approx(math.exp(-1.0 * 0.6))  # inside the layer: 60 % of it above
    assert f[3] == 1.0                                  # above the layer top


def test_sun_weight_extremes():
    p = CloudShadowSettings(direct_fraction=0.8, horizon_fade=0.1)
    assert reference.direct_weight((0, 1, 0), (1, 1, 1), p) == pytest.approx(0.8)
    assert reference.direct_weight((1, 0, 0), (1, 1, 1), p) == 0.0               # on the horizon
    assert reference.direct_weight((1, -0.2, 0), (1, 1, 1), p) == 0.0            # below it
    assert reference.direct_weight((0, 1, 0), (0, 0, 0), p) == 0.0               # night: no sun colour
    assert reference.direct_weight((0, 0, 0), (1, 1, 1), p) == 0.0               # no direction
    assert reference.direct_weight((1, 0.01, 0), (1, 1, 1), p) < 0.03            # grazing: fading out
    for bad in (dict(direct_fraction=1.5), dict(horizon_fade=0.0), dict(strength=-1), dict(sigma=math.nan),
                dict(cell_size=(1, 0, 1)), dict(base_altitude="high")):
        name = next(iter(bad))
        with pytest.raises(ValueError, match=name):
            CloudShadowSettings(**bad)
    with pytest.raises(ValueError, match="unknown"):
        p.replace(strenght=2.0)
    assert p.replace(strength=2.0).strength == 2.0 and p.strength == 1.0


@pytest.fixture(scope="module")
def scene_gpu():
    g = create_headless((160, 90))
    yield g
    g.release()


def scene_colour(gpu, app, sun: Sun, sums=None):
    """The scene's HDR colour (GL rows) and tone-mapped pixels with ``sun``, optionally forced sums."""
    sim = app.resource(CloudSimulation)
    if sums is not None:
        for s in sim.view()[:2]:
            write_sums(sim, s, sums)
    app.insert_resource(sun)
    app.render()
    probe = next(p for p in app.graph.passes if isinstance(p, CapturePass))
    return probe.color.copy(), gpu.read_pixels()


@pytest.mark.parametrize("case", ["overhead", "grazing", "horizon", "night", "empty", "full"])
def test_extremes_no_nan_and_the_right_darkening(scene_gpu, case):
    gpu = scene_gpu
    gpu.make_current()
    params = CloudShadowSettings(base_altitude=60.0, cell_size=(6.0, 3.0, 6.0))
    wp = weather((32, 8, 32), cloud_density=0 if case == "empty" else 30)
    app, sim, _, _ = shadow_app(gpu, params, wp, cell_size=(6.0, 3.0, 6.0), warmup=12, scene=True)
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 150.0, 200.0])
    cam.look_at((0.0, 0.0, 0.0))
    sun = {"overhead": Sun(np.array([0.0, 1.0, 0.0])), "grazing": Sun.from_angles(0.3, 30.0),
           "horizon": Sun.from_angles(0.0, 30.0), "night": Sun.from_angles(-12.0, 30.0),
           "empty": Sun.from_angles(50.0, 30.0), "full": Sun.from_angles(50.0, 30.0)}[case]
    layers = 1 + sim.maps_of(sim.view()[0]).bands
    sums = np.full((layers, 32, 32), 1e6, np.float32) if case == "full" else None
    plugin = next(p for p in app.plugins if isinstance(p, CloudShadowsPlugin))
    plugin.configure(strength=0.0)
    base, _ = scene_colour(gpu, app, sun, sums)
    plugin.configure(strength=params.strength)
    shaded, pixels = scene_colour(gpu, app, sun, sums)
    assert gpu.ctx.error == "GL_NO_ERROR"
    assert np.isfinite(shaded).all() and np.isfinite(base).all()
    ratio = shaded[..., :3] / np.maximum(base[..., :3], 1e-6)
    assert ratio.max() <= 1.0 + 2e-3, "shadows only darken"
    if case in ("horizon", "night", "empty"):
        assert np.array_equal(shaded, base)
    elif case == "grazing":
        assert ratio.min() > 0.97
    elif case == "overhead":
        assert ratio.min() < 0.8 and (ratio[..., 1] > 0.999).mean() > 0.2   # blotches, not a veil
    elif case == "full":
        under = ratio[..., 1] < 0.5
        assert under.mean() > 0.05
        weight = reference.direct_weight(sun.direction, sun.color, params)
        assert np.allclose(ratio[under], 1.0 - weight, atol=3e-3)
    save_png(f"cloud_shadows_extreme_{case}.png", pixels)
    app.close()


def test_shadows_on_the_ground_look_right_and_move_with_the_clouds():
    """A camera above the layer looking down at an angle: blotches on the ground, drifting with the wind."""
    gpu = create_headless((480, 270))
    cell = (6.0, 3.0, 6.0)
    params = CloudShadowSettings(base_altitude=120.0, cell_size=cell, strength=1.5)
    wp = weather((64, 16, 64), cloud_density=25, cloud_size=9.0, cloud_size_variance=3.0, region_margin=10.0,
                 wind=(1.5, 0.0, 0.5))
    app, sim, _, _ = shadow_app(gpu, params, wp, cell_size=cell, warmup=30, scene=True, origin=(-32, -32))
    app.insert_resource(Sun.from_angles(60.0, 200.0))
    cam = app.resource(Camera)
    cam.far = 3000.0
    cam.position = np.array([0.0, 180.0, 250.0])                # above the layer (120..168 m)
    cam.look_at((0.0, 0.0, -20.0))
    frames = []
    for _ in range(2):
        app.run_frames(40, 1 / 30)
        frames.append(gpu.read_pixels())
        save_png(f"cloud_shadows_ground_{len(frames)}.png", frames[-1])
    plugin = next(p for p in app.plugins if isinstance(p, CloudShadowsPlugin))
    plugin.configure(strength=0.0)
    app.render()
    plain = gpu.read_pixels()
    save_png("cloud_shadows_ground_without.png", plain)
    assert gpu.ctx.error == "GL_NO_ERROR"
    lum = [f.astype(float).mean(-1) for f in frames]
    dark = lum[1] < plain.astype(float).mean(-1) - 10
    assert 0.03 < dark.mean() < 0.6, "shadow blotches cover part of the ground"
    assert np.abs(lum[0] - lum[1]).mean() > 0.5, "the shadows move as the clouds drift"
    app.close()
    gpu.release()


def test_shadows_continue_with_the_far_field_beyond_the_volume(gpu, ctx):
    """Past the volume the ground is shadowed by the far field's cover (numpy reference), darker under
    its clouds than under its gaps; without the far field it is fully lit there."""
    from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
    from atmos.plugins.clouds.far_field.layer import column_tau, drift
    from atmos.plugins.clouds.far_field.reference import far_optical_depth
    from atmos.plugins.clouds.far_field.cover import fbm_quantiles
    size = gpu.size
    params = CloudShadowSettings(base_altitude=60.0, cell_size=(4.0, 2.0, 4.0), sigma=0.5)
    fill, probe = FillPass(), CapturePass()
    settings = CloudSettings(smoothing_slices=2, group_size=(8, 8), shading=False, cell_size=(4.0, 2.0, 4.0),
                             edge_fade=0.3)
    far = CloudFarFieldPlugin(tile_size=400.0, size=64, animate=False)
    app = App(gpu).insert_resource(VolumeOrigin(-8.0, 0.0, -8.0))
    app.add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(settings, weather=weather(), seed=5),
                    pass_plugin(fill), CloudShadowsPlugin(params), far, pass_plugin(probe))
    app.startup()
    sim = app.resource(CloudSimulation)
    app.update(1 / 30)
    a, b, t = sim.view()
    layers = 1 + sim.maps_of(a).bands
    nx, nz = np.array(sim.shape)[[0, 2]]
    sums = np.zeros((layers, nx, nz))
    sums[:, : nx // 2] = 3.0 * sim.settings.cover_threshold + 1.0             # half the columns covered
    for s in (a, b):
        write_sums(sim, s, sums)
    sun = Sun.from_angles(60.0, 30.0)
    app.insert_resource(sun)
    cam = app.resource(Camera)
    cam.near, cam.far = 1.0, 2000.0
    cam.position = np.array([150.0, 40.0, 0.0])
    cam.look_at(np.array([250.0, 0.0, 30.0]))
    rays = ray_dirs(cam, size)
    ground = np.where(rays[..., 1] < 0, cam.position[1] / np.maximum(-rays[..., 1], 1e-9), np.inf)
    fill.depth = np.where(ground < 1500.0, depth_of(cam, size, cam.position + rays * np.minimum(ground, 1500.0)[..., None]),
                          1.0)                              # ground to 1.5 km, sky (depth 1) beyond
    fill.color = np.ones((size[1], size[0], 4))
    app.render()
    factor = probe.color[..., 0].astype(np.float64)
    layer = far.layer
    cover, columns = layer.read_cover()
    octaves = [layer.octaves.download(k) for k in range(4)]
    fs = far.settings
    sets = sim.sets()
    far_tau = lambda xz: params.strength * far_optical_depth(    # the column the far field draws
        xz, octaves, drift(fs, sets, 0.0, layer.tile_size), layer.tile_size, fbm_quantiles(fs.base_frequency, fs.seed, fs.size), columns,
        column_tau(fs, sets))
    points = world_points(cam, size, probe.depth)
    weight = reference.direct_weight(sun.direction, sun.color, params)
    assert 0.2 < cover < 0.8
    expected = reference.shadow_factor(points, sums[0], sums[0], t, sun.direction, weight,
                                       params.sigma, cloud_layout(sets, params), sets.a_shift, settings.edge_fade,
                                       far=far_tau)
    expected[probe.depth >= 1.0] = 1.0
    ground_px = probe.depth < 1.0
    error = np.abs(factor - expected)[ground_px]
    # float32 depth far away (llvmpipe: p95 2.3e-4, mean 1e-4); the rank table of a 256-texel layer instead of
    # the layer's own (64): p95 1e-2, mean 1e-3; a wrong drift or texel offset: errors ~0.2
    assert np.quantile(error, 0.95) < 3e-3 and error.mean() < 5e-4, f"far-field shadow differs from numpy: {error.mean():.3g}"
    under, gap = ground_px & (expected < 0.5), ground_px & (expected > 0.99)
    assert under.sum() > 50 and gap.sum() > 50, "the view has far-field clouds and gaps"
    assert factor[under].mean() < factor[gap].mean() - 0.3
    save_png("shadows_far_field.png", np.clip(factor[::-1] * 255, 0, 255).astype(np.uint8))
    shadows = next(p for p in app.plugins if isinstance(p, CloudShadowsPlugin))
    shadows.configure(far_field=False)
    app.render()
    beyond = ground_px & (reference.shadow_factor(points, sums[0], sums[0], t, sun.direction, weight, params.sigma,
                                                  cloud_layout(sets, params), sets.a_shift, settings.edge_fade) > 0.999)
    assert beyond.mean() > 0.5
    assert np.abs(probe.color[..., 0][beyond] - 1.0).max() < 2e-3, "far_field=False: fully lit past the volume"
    app.close()


@pytest.mark.parametrize("kind", ["stratus", "cumulus", "congestus"])
def test_a_typed_clouds_shadow_falls_where_the_sun_meets_the_cloud_drawn(kind):
    """With a cloud type, the sun's optical depth (reference.sun_optical_depth, column.glsl's twin; the GPU
    bake and the exact path match it in test_cloud_shadow_map) is read where the sun's ray meets the
    height of the shape's mass centre, not the layer's middle: the shadow of one full column on the ground
    under a 25° sun is centred within 1.5 cells of the drawn density's own shadow (the shaped density
    integrated along each slanted ray; the column's bilinear edges are thinner, lower clouds, which the
    full column's centre does not follow: 0.05 / 0.2 / 1.0 cells here), where the middle plane put it
    3.7 (cumulus) to 7 (congestus) cells away, and at least 3 times as far."""
    from atmos.plugins.clouds.volume.shape import CLOUD_TYPES, type_breakpoints, type_density, typed_column
    t = CLOUD_TYPES[kind]
    layout = CloudLayout(shape=(48, 8, 8), cell=(40.0, 40.0, 40.0), origin_xz=(-24.0, -4.0), base=1000.0, group=(8, 8))
    nx, ny, nz = layout.shape
    sums = np.zeros((nx, nz))
    sums[30:32, 3:5] = 0.35 * ny                                   # one full column (2 x 2 cells)
    e = math.radians(25.0)
    sun = np.array([math.cos(e), math.sin(e), 0.0])
    centre_z = 0.5 * (layout.lo[2] + layout.hi[2]) - 0.5 * layout.cell[2]
    x = np.linspace(-4000.0, 0.0, 1601)
    ground = np.stack([x, np.zeros_like(x), np.full_like(x, centre_z)], -1)
    tau = reference.sun_optical_depth(ground, sums, sums, 0.0, sun, 1.0, layout, cloud_type=t)

    def texel(xz):
        return (xz - layout.lo[[0, 2]]) / np.asarray(layout.cell)[[0, 2]] - 0.5
    thickness = layout.hi[1] - layout.lo[1]
    top = max(float(type_breakpoints(t)[2]), 1.0)
    h = (np.arange(256) + 0.5) / 256 * top                        # the drawn density along each slanted ray
    y = layout.lo[1] + h * thickness
    xz = ground[:, None, [0, 2]] + (y[None, :, None] / sun[1]) * sun[[0, 2]]
    m = reference.zero_border_bilinear(sums, texel(xz)) / ny
    drawn = (type_density(m, h[None, :], t) * top / 256 * ny).sum(-1)
    mid = ground[:, [0, 2]] + (0.5 * (layout.lo[1] + layout.hi[1]) / sun[1]) * sun[[0, 2]]
    middle = typed_column(reference.zero_border_bilinear(sums, texel(mid)), mid[:, 0], mid[:, 1], ny, t)

    def centre(w):
        return float((w * x).sum() / w.sum())
    cell = layout.cell[0]
    assert drawn.max() > 0 and tau.max() > 0
    err, moved = abs(centre(tau) - centre(drawn)) / cell, abs(centre(middle) - centre(drawn)) / cell
    print(f"{kind}: shadow {centre(tau):.0f} m, drawn {centre(drawn):.0f} m, middle plane {centre(middle):.0f} m")
    assert err < 1.5, f"{kind}: shadow at {centre(tau):.0f} m, the cloud's at {centre(drawn):.0f} m"
    assert moved > max(3.0, 3.0 * err), f"{kind}: the middle plane was {moved:.1f} cells off"
