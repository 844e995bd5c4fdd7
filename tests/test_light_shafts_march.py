"""Light shafts marched through the cloud shadow map: GPU against the float64 reference, a lit gap
between two cloud columns seen as a streak, extremes, and a look at the image."""
import math
import os

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera, view_basis
from atmos.defaults import DefaultPlugins
from atmos.froxels import froxel_jitter
from atmos.gpu import create_headless
from atmos.graph import PassBuilder, RenderPass
from atmos.lighting import Sun
from atmos.plugins.clouds.shadows import reference as shadow_reference
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.clouds.volume.sets import CLOUD_SETS
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.light_shafts import LightShaftsPlugin, reference
from atmos.plugins.light_shafts.froxels import SHAFT_VOLUME
from atmos.plugins.light_shafts.march import SHAFT_COLOR, SHAFT_DEPTH, march_irradiance
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.render_core import CapturePass
from tests.test_cloud_shadows import pass_plugin

OUT = os.path.join(os.path.dirname(__file__), "..", "out")
SIZE = (128, 72)
CELL = (20.0, 25.0, 20.0)
BASE = 200.0


class MarchProbe(RenderPass):
    """Reads the march's low-res targets and the cloud sets back after the light-shafts pass."""
    name = "z_march_probe"
    phase = "post"

    def __init__(self):
        self.low = self.depth = self.sets = None

    def setup(self, builder: PassBuilder) -> None:
        for name in (SHAFT_COLOR, SHAFT_DEPTH, CLOUD_SETS):
            builder.read(name)
        builder.side_effect()

    def execute(self, frame) -> None:
        t = frame.resource(SHAFT_COLOR)
        w, h = t.size
        self.low = np.frombuffer(t.read(), np.float16).reshape(h, w, 4).astype(np.float64)
        d = frame.resource(SHAFT_DEPTH)
        self.depth = np.frombuffer(d.read(), np.float32).reshape(h, w).astype(np.float64)
        self.sets = frame.resource(CLOUD_SETS)


def columns_volume(shape=(32, 4, 32)) -> np.ndarray:
    """Two cloud slabs, x cells [2, 14) and [18, 30) (40..280 m and 360..600 m), all z, with an 80 m
    gap between them around x = 320 m."""
    v = np.zeros(shape, np.float32)
    v[2:14] = 1.0
    v[18:30] = 1.0
    return v


def march_app(gpu, density, probe, **shafts):
    settings = CloudSettings(cell_size=CELL, base_altitude=BASE, shading=False, sigma_t=0.05)
    plugin = LightShaftsPlugin(**shafts)
    capture = CapturePass()
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(settings, density=density),
                               SkyGradientPlugin(), GroundPlugin(), plugin, pass_plugin(probe), pass_plugin(capture))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([320.0, 60.0, 20.0])
    cam.yaw, cam.pitch, cam.far = math.pi, 0.25, 5000.0          # looking +z along the gap, a little up
    return app, plugin, capture


def sun_tau(sets, sun_dir):
    """The sun's optical depth through the cloud sets at points (..., 3): the exact column sums."""
    a, b, t = sets.view()
    return lambda p: shadow_reference.sun_optical_depth(p, sets.maps_of(a).read_sums()[0], sets.maps_of(b).read_sums()[0],
                                                        t, sun_dir, sets.settings.sigma, sets.layout(), sets.a_shift)


def expected(app, probe, settings):
    """The reference march for what the probe read back (the GPU's own low-res depth)."""
    cam, sun = app.resource(Camera), app.resource(Sun)
    tau = sun_tau(probe.sets, np.asarray(sun.direction) / np.linalg.norm(sun.direction))
    return reference.march_shafts(probe.depth, view_basis(cam, SIZE[0] / SIZE[1]), cam.position, cam.near, cam.far,
                                  SIZE, settings.downsample, np.asarray(sun.direction) / np.linalg.norm(sun.direction),
                                  march_irradiance(sun, settings), settings, tau)


@pytest.fixture(scope="module")
def march_gpu():
    gpu = create_headless(SIZE)
    yield gpu
    gpu.release()


@pytest.mark.parametrize("downsample, steps", [(2, 24), (1, 7), (3, 40)])
def test_gpu_march_matches_the_float64_reference(march_gpu, rng, downsample, steps):
    density = (rng.random((16, 4, 16)) > 0.6).astype(np.float32) * rng.uniform(0.2, 1.5, (16, 4, 16)).astype(np.float32)
    probe = MarchProbe()
    app, plugin, _ = march_app(march_gpu, density, probe, downsample=downsample, steps=steps, scattering=3e-4,
                               froxels=None)
    app.insert_resource(Sun(np.array([0.3, 0.8, 0.4]), (1.0, 0.8, 0.6)))
    app.render()
    assert march_gpu.ctx.error == "GL_NO_ERROR"
    want = expected(app, probe, plugin.settings)
    got = probe.low
    assert got.shape == want.shape and np.isfinite(got).all()
    scale = want[..., :3].max()
    assert scale > 0.05
    # f2 target, float32 sums and positions: within a few per mille of the brightest texel
    assert np.abs(got[..., :3] - want[..., :3]).max() < 4e-3 * scale + 1e-3
    assert np.allclose(got[..., 3], want[..., 3], atol=2e-3)
    app.close()


class VolumeProbe(RenderPass):
    """Reads the froxel volume (W, H, D + 1, 4) and the cloud sets back after the light-shafts pass."""
    name = "z_volume_probe"
    phase = "post"
    volume = sets = None

    def setup(self, builder: PassBuilder) -> None:
        builder.read(SHAFT_VOLUME)
        builder.read(CLOUD_SETS)
        builder.side_effect()

    def execute(self, frame) -> None:
        t = frame.resource(SHAFT_VOLUME)
        w, h, d = t.size
        self.volume = np.frombuffer(t.read(), np.float16).reshape(d, h, w, 4).transpose(2, 1, 0, 3).astype(np.float64)
        self.sets = frame.resource(CLOUD_SETS)


@pytest.mark.parametrize("froxels", [(32, 18, 48), (9, 5, 3)])
def test_gpu_froxels_match_the_float64_twin(march_gpu, rng, froxels):
    """LightShaftSettings.froxels: the volume against reference.froxel_shafts (the same cloud shadows as
    the march's test), and the frame against the volume read back and composited by reference.froxel_apply
    over the frame without shafts."""
    density = (rng.random((16, 4, 16)) > 0.6).astype(np.float32) * rng.uniform(0.2, 1.5, (16, 4, 16)).astype(np.float32)
    probe = VolumeProbe()
    app, plugin, capture = march_app(march_gpu, density, probe, froxels=froxels, scattering=3e-4,
                                     max_distance=rng.uniform(800.0, 4000.0))
    app.insert_resource(Sun(np.array([0.3, 0.8, 0.4]), (1.0, 0.8, 0.6)))
    app.render()
    assert march_gpu.ctx.error == "GL_NO_ERROR"
    settings, cam, sun = plugin.settings, app.resource(Camera), app.resource(Sun)
    sun_dir = np.asarray(sun.direction) / np.linalg.norm(sun.direction)
    tau = sun_tau(probe.sets, sun_dir)
    basis = view_basis(cam, SIZE[0] / SIZE[1])
    want = reference.froxel_shafts(cam.position, basis, froxels, sun_dir, march_irradiance(sun, settings), settings, tau)
    got = probe.volume
    assert got.shape == want.shape and np.isfinite(got).all()
    scale = want[..., :3].max()
    assert scale > 0.05
    # f2 volume, float32 sums and positions, the shadow map against exact column sums: as the march's
    assert np.abs(got[..., :3] - want[..., :3]).max() < 4e-3 * scale + 1e-3
    assert np.allclose(got[..., 3], want[..., 3], atol=2e-3)
    shafts, depth = capture.color[..., :3].copy(), capture.depth.copy()
    plugin.configure(scattering=0.0)                    # no light to scatter: the pass draws nothing
    app.render()
    composited = reference.froxel_apply(got, capture.color, depth, basis, cam.near, cam.far, settings)
    # the f2 colour; the texture unit's trilinear weights (8 bits on common hardware): 1/256 of a neighbour's step
    step = np.abs(np.diff(got, axis=2)).max()
    assert np.abs(shafts - composited).max() < 2e-3 * max(composited.max(), 1.0) + step / 256, \
        np.abs(shafts - composited).max()
    app.close()


def test_a_gap_between_cloud_columns_is_a_brighter_streak(march_gpu):
    """Looking along the gap between two cloud slabs with the sun high above: the air in the gap is
    lit, the air under the slabs is in their shadow, so the shafts add a bright vertical streak in
    the middle of the image and much less beside it; screen mode (no ray through the shadow map)
    has no such streak."""
    probe = MarchProbe()
    app, plugin, capture = march_app(march_gpu, columns_volume(), probe, downsample=2, steps=48, scattering=4e-4,
                                     max_distance=500.0, froxels=None)
    app.insert_resource(Sun(np.array([0.0, 1.0, 0.25]), (1.0, 0.95, 0.9)))
    app.render()
    light = probe.low[..., :3].mean(axis=-1)           # in-scattered light of the low-res texels
    assert np.isfinite(probe.low).all() and light.min() >= 0.0
    lum = light.mean(axis=0)                           # per image column
    w = lum.size
    centre = lum[int(0.45 * w):int(0.55 * w)].mean()
    sides = np.concatenate([lum[int(0.02 * w):int(0.2 * w)], lum[int(0.8 * w):int(0.98 * w)]]).mean()
    assert centre > 3.0 * sides, (centre, sides)
    final = capture.color[..., :3].astype(np.float64).mean(axis=(0, 2))
    W = SIZE[0]
    assert final[int(0.45 * W):int(0.55 * W)].mean() > 1.1 * final[int(0.02 * W):int(0.2 * W)].mean()
    os.makedirs(OUT, exist_ok=True)
    from PIL import Image
    img = np.clip(capture.color[::-1, :, :3].astype(np.float64), 0, 1) ** (1 / 2.2)
    Image.fromarray((img * 255).astype(np.uint8)).resize((SIZE[0] * 4, SIZE[1] * 4), Image.NEAREST).save(
        os.path.join(OUT, "light_shafts_gap.png"))
    app.close()


@pytest.mark.parametrize("froxels", [None, (160, 90, 64), (1, 1, 1)])
@pytest.mark.parametrize("case", ["sun_below", "black_sun", "grazing", "no_clouds"])
def test_march_extremes(case, froxels):
    gpu = create_headless((48, 27))
    try:
        plugin = LightShaftsPlugin(scattering=1e-3, max_distance=1e6, froxels=froxels)
        capture = CapturePass()
        plugins = [DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(), plugin, pass_plugin(capture)]
        if case != "no_clouds":
            plugins.insert(1, CloudsPlugin(CloudSettings(cell_size=CELL, shading=False), density=columns_volume()))
        app = App(gpu).add_plugins(*plugins)
        app.startup()
        sun = {"sun_below": Sun(np.array([0.0, -0.2, 1.0])), "black_sun": Sun(np.array([0.0, 1.0, 0.0]), (0, 0, 0)),
               "grazing": Sun(np.array([0.0, 1e-6, 1.0])), "no_clouds": Sun(np.array([0.0, 0.5, 1.0]))}[case]
        app.insert_resource(sun)
        cam = app.resource(Camera)
        cam.position, cam.yaw, cam.pitch = np.array([160.0, 30.0, -100.0]), math.pi, 0.1
        app.render()
        assert gpu.ctx.error == "GL_NO_ERROR"
        assert np.isfinite(capture.color).all()
        if case == "no_clouds":                   # unshadowed haze: the march still draws
            haze = capture.color.copy()
            plugin.configure(scattering=0.0)
            app.render()
            assert np.abs(haze - capture.color).max() > 0.01
        app.close()
    finally:
        gpu.release()


def test_froxel_history_averages_the_jittered_slices_of_a_still_view(march_gpu, rng):
    """LightShaftSettings.froxel_history: each frame samples its slices at froxel_jitter of that frame and
    a still camera over still clouds averages the frames (a running mean while 1/(n + 1) > the blend): after
    six frames the volume is the mean of reference.froxel_shafts at the six jitters (the first at the middle) — not the middle's
    volume, which a shadow edge inside a slice changes; a frame drawn again without advancing restarts
    from its own fresh volume."""
    density = (rng.random((16, 4, 16)) > 0.6).astype(np.float32) * rng.uniform(0.2, 1.5, (16, 4, 16)).astype(np.float32)
    probe = VolumeProbe()
    froxels = (24, 14, 12)
    app, plugin, _ = march_app(march_gpu, density, probe, froxels=froxels, scattering=3e-4, max_distance=3000.0,
                               froxel_history=0.1)
    app.insert_resource(Sun(np.array([0.3, 0.8, 0.4]), (1.0, 0.8, 0.6)))
    frames = []
    for _ in range(6):
        app.update(0.0)                     # no simulation step: the clouds stay; the frame index advances
        frames.append(app.clock.frame)
    history = next(p for p in app.graph.passes if p.name == "light_shafts").froxels.history
    got = history.read()
    assert history.frames == 6 and march_gpu.ctx.error == "GL_NO_ERROR"
    settings, cam, sun = plugin.settings, app.resource(Camera), app.resource(Sun)
    sun_dir = np.asarray(sun.direction) / np.linalg.norm(sun.direction)
    tau = sun_tau(probe.sets, sun_dir)
    basis = view_basis(cam, SIZE[0] / SIZE[1])
    def volume(jitter):
        return reference.froxel_shafts(cam.position, basis, froxels, sun_dir, march_irradiance(sun, settings),
                                       settings, tau, jitter)
    jitters = [0.5] + [froxel_jitter(n) for n in frames[1:]]      # the first frame: the middle
    assert len(set(jitters)) == 6
    want = np.mean([volume(j) for j in jitters], axis=0)
    middle = volume(0.5)
    scale = want[..., :3].max()
    bound = 4e-3 * scale + 1e-3 + 6 * 2.0 ** -11 * scale          # as the volume's test, and six f2 blends
    assert np.abs(got[..., :3] - want[..., :3]).max() < bound
    assert np.allclose(got[..., 3], want[..., 3], atol=2e-3)
    off_mean, off_middle = (np.abs(got[..., :3] - v[..., :3]).max() for v in (want, middle))
    assert off_middle > 3 * off_mean, ("the jitter must move the samples", off_mean, off_middle)
    app.render()                                   # the same frame again: no history to blend
    assert history.frames == 1 and np.array_equal(history.read(), probe.volume)
    app.close()
