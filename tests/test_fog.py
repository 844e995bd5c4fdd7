"""Fog post-process: GPU noise, factors and blend against the float64 references; extremes; errors; scenes."""
import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera
from atmos.cli import main as cli
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.graph import RenderPass
from atmos.plugins.fog import FogPlugin, FogSettings, apply_fog
from atmos.plugins.fog.factors import apply_fog_ref, fog_factor, height_depth
from atmos.plugins.fog.noise import (NoiseVolumes, noise_volume_ref, octave_key, periodic_noise,
                                     sample_repeat_trilinear)
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.terrain import TerrainPlugin, heightfield
from atmos.render_core import CapturePass, COLOR, DEPTH

SMALL = (4, 8, 16, 32)
TOL = 2e-4          # float32 GPU vs float64 reference
TEX_TOL = 4e-3      # texture variant: GPUs filter with ~8-bit sub-texel weights (llvmpipe: exact)


def random_inputs(rng, h=23, w=31):
    color = rng.random((h, w, 3), dtype=np.float32)
    distance = (rng.random((h, w)) ** 2 * 300).astype(np.float32)
    distance[0, :4] = np.inf
    distance[1, :3] = 0.0
    positions = (rng.random((h, w, 3)) * 600 - 300).astype(np.float32)
    return color, distance, positions


def reference_volumes(settings):
    return [noise_volume_ref(settings.resolutions[i], settings.texels_per_cell, octave_key(settings.seed, i))
            for i in range(settings.octaves)]


# -- noise ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("tpc", [1, 3])
def test_gpu_noise_volumes_match_reference_and_fill_every_texel(gpu, ctx, rng, tpc):
    settings = FogSettings(mode="hetero_exp", resolutions=(4, 8, 16, 24), texels_per_cell=tpc,
                           seed=int(rng.integers(2**32)))
    volumes = NoiseVolumes(gpu, settings, fill=np.nan)
    got = volumes.read()
    volumes.release()
    for vol, ref in zip(got, reference_volumes(settings)):
        assert vol.shape == ref.shape and not np.isnan(vol).any()
        np.testing.assert_allclose(vol, ref, atol=1e-5)  # float32 texel positions
        # 3D Perlin noise with the 12 edge gradients peaks a little above 1 (about 1.04)
        assert 0.15 < ref.std() < 0.45 and np.abs(ref).max() <= 1.04


def test_noise_is_periodic_and_continuous_across_the_tile_edge(rng):
    key = octave_key(int(rng.integers(2**32)), 2)
    q = rng.random((200, 3)) * 50 - 25
    for axis in range(3):
        shift = np.zeros(3)
        shift[axis] = 16
        np.testing.assert_allclose(periodic_noise(q + shift, 16, key), periodic_noise(q, 16, key), atol=1e-12)
    line = np.stack([np.linspace(15.9, 16.1, 101), np.full(101, 3.3), np.full(101, 7.7)], -1)
    assert np.abs(np.diff(periodic_noise(line, 16, key))).max() < 0.01     # no seam at the wrap
    vol = noise_volume_ref(8, 2, key)
    u = np.stack([np.linspace(-0.01, 0.01, 41), np.full(41, 0.3), np.full(41, 0.6)], -1)
    assert np.abs(np.diff(sample_repeat_trilinear(vol, u))).max() < 0.05  # the texture wraps smoothly


# -- factors -------------------------------------------------------------------------------------
def test_reference_factors_follow_the_equations(rng):
    d = rng.random(50) * 100
    np.testing.assert_allclose(fog_factor("linear", d, start=10, end=90), np.clip((90 - d) / 80, 0, 1))
    np.testing.assert_allclose(fog_factor("exp", d, 0.044), np.exp(-d * 0.044))
    np.testing.assert_allclose(fog_factor("exp2", d, 0.044), np.exp(-(d * 0.044) ** 2))
    t = rng.random(50) * 1.875
    np.testing.assert_allclose(fog_factor("hetero_exp", d, 0.06, turbulence=t), np.exp(-d * 0.06 * t))
    np.testing.assert_allclose(fog_factor("hetero_exp2", d, 0.06, turbulence=t), np.exp(-(d * 0.06 * t) ** 2))


@pytest.mark.parametrize("mode", ["linear", "exp", "exp2", "hetero_exp", "hetero_exp2"])
def test_reference_factor_extremes_stay_in_unit_interval(mode):
    d = np.array([0.0, 1e-30, 1.0, 1e6, 1e30, 1e38, np.inf])
    for g in (0.0, 1e-30, 0.044, 1e30):
        for t in (0.0, 1e-30, 1.0, 1.875):
            f = fog_factor(mode, d, g, 0.0, 100.0, t)
            assert np.isfinite(f).all() and (f >= 0).all() and (f <= 1).all()
            if mode != "linear":
                assert f[0] == 1.0                     # distance 0: no fog
                medium = g * (t if mode.startswith("hetero") else 1.0)
                if medium == 0 or medium >= 1e-30:
                    assert f[-1] == (1.0 if medium == 0 else 0.0)     # the limit at infinity


def test_height_fog_depth_is_the_integral_of_its_density_along_the_ray(rng):
    """The closed form against a quadrature of g e^(-(y - base)/H) on fresh random rays: climbing,
    falling, level (slope 1e-9), from below and far above the base, short and long."""
    for slope in (*rng.uniform(-1, 1, 6), 1e-9, -1e-9, 0.0):
        d, eye, base, scale, g = rng.uniform(0.5, 3000), rng.uniform(-100, 600), rng.uniform(-30, 60), \
            rng.uniform(3, 300), rng.uniform(1e-4, 0.05)
        s = np.linspace(0.0, d, 400001)
        quad = np.trapezoid(g * np.exp(-(eye + slope * s - base) / scale), s)
        got = height_depth(d, g, eye, slope, base, scale)
        assert got == pytest.approx(min(quad, 1e4), rel=1e-6), (slope, d, eye, base, scale)


def test_height_fog_is_thick_in_the_valley_and_thin_above_and_never_nan():
    d = np.array([0.0, 1e-30, 10.0, 1e3, 1e6, 3e38, np.inf])
    low = fog_factor("height", d, 0.05, eye_y=0.0, slope=0.0, base=0.0, scale=20.0)
    high = fog_factor("height", d, 0.05, eye_y=200.0, slope=0.0, base=0.0, scale=20.0)
    assert (high >= low).all() and high[3] > 0.99 and low[3] < 1e-6          # 10 scale heights up: clear
    up = fog_factor("height", d, 0.05, eye_y=0.0, slope=0.5, base=0.0, scale=20.0)
    assert up[-1] == pytest.approx(np.exp(-0.05 * 20.0 / 0.5))              # the sky: a finite column above
    for eye in (-1e6, -50.0, 0.0, 1e6):
        for g in (0.0, 1e-30, 0.05, 1e30):
            for slope in (-1.0, -1e-9, 0.0, 0.3):
                f = fog_factor("height", d, g, eye_y=eye, slope=slope, base=0.0, scale=20.0)
                assert np.isfinite(f).all() and (f >= 0).all() and (f <= 1).all() and f[0] == 1.0


@pytest.mark.parametrize("mode,extra", [("height", {}), ("hetero_height", {"noise": "procedural", "resolutions": SMALL}),
                                        ("height", {"sky": "keep", "density": 0.2, "scale_height": 4.0})])
def test_height_fog_on_the_gpu_matches_the_reference(gpu, ctx, rng, mode, extra):
    color, distance, _ = random_inputs(rng)
    camera = rng.uniform(-20, 40, 3)
    dirs = rng.normal(size=color.shape)
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    reach = np.where(np.isinf(distance), 1e4, distance)[..., None]
    positions = (camera + dirs * reach).astype(np.float32)
    kw = {"height_base": float(rng.uniform(-10, 10)), "scale_height": float(rng.uniform(5, 40)), "density": 0.03, **extra}
    out = apply_fog(gpu, color, distance, mode=mode, positions=positions, camera=tuple(camera), far=500.0, **kw)
    settings = FogSettings(mode=mode, **kw)
    ref = apply_fog_ref(color, distance, settings, positions, far=500.0, camera=tuple(camera))
    assert np.isfinite(out).all()
    np.testing.assert_allclose(out, ref, atol=TOL)
    assert np.abs(ref - color).max() > 0.1                     # the fog really changed the picture


# -- apply_fog against the reference -------------------------------------------------------------
@pytest.mark.parametrize("mode,extra,tol", [
    ("linear", {"start": 5.0, "end": 120.0}, TOL), ("exp", {}, TOL), ("exp2", {"density": 0.02}, TOL),
    ("hetero_exp", {"noise": "procedural"}, TOL), ("hetero_exp2", {"noise": "procedural", "density": 0.01}, TOL),
    ("hetero_exp", {"noise": "texture"}, TEX_TOL), ("hetero_exp2", {"noise": "texture", "texels_per_cell": 2}, TEX_TOL),
    ("hetero_exp2", {"noise": "procedural", "octaves": 2, "amplitude": 0.5, "sky": "keep"}, TOL),
])
def test_apply_fog_matches_reference(gpu, ctx, rng, mode, extra, tol):
    color, distance, positions = random_inputs(rng)
    kw = dict(extra)
    if mode.startswith("hetero"):
        kw.update(resolutions=SMALL, seed=int(rng.integers(2**32)), tile_size=float(rng.uniform(40, 300)))
    time = float(rng.uniform(0, 100))
    out = apply_fog(gpu, color, distance, mode=mode, positions=positions, time=time, **kw)
    settings = FogSettings(mode=mode, **kw)
    volumes = reference_volumes(settings) if settings.heterogeneous and settings.noise == "texture" else None
    ref = apply_fog_ref(color, distance, settings, positions, time, volumes=volumes)
    assert out.dtype == np.float32 and out.shape == color.shape and np.isfinite(out).all()
    np.testing.assert_allclose(out, ref, atol=tol)
    assert np.abs(ref - color).max() > 0.1                     # the fog really changed the picture


@pytest.mark.parametrize("sky", ["fog", "keep"])
def test_apply_fog_writes_every_pixel(gpu, ctx, rng, sky):
    color = rng.random((17, 40, 3), dtype=np.float32)
    distance = np.full((17, 40), np.inf, np.float32)
    out = apply_fog(gpu, color, distance, mode="exp", density=0.1, fog_color=(0.2, 0.5, 0.7), sky=sky)
    expected = np.broadcast_to([0.2, 0.5, 0.7], color.shape) if sky == "fog" else color
    np.testing.assert_allclose(out, expected, atol=1e-6)


@pytest.mark.parametrize("mode", ["exp", "exp2", "hetero_exp", "hetero_exp2", "linear"])
@pytest.mark.parametrize("density", [0.0, 1e-30, 1e30])
def test_apply_fog_extremes_never_nan(gpu, ctx, rng, mode, density):
    color = rng.random((4, 5, 3), dtype=np.float32)
    distance = np.array([[0, 1e-30, 1, 1e6, np.inf]] * 4, np.float32)
    positions = (rng.random((4, 5, 3)) * 1e4).astype(np.float32)
    kw = {"resolutions": SMALL, "noise": "procedural"} if mode.startswith("hetero") else {}
    out = apply_fog(gpu, color, distance, mode=mode, density=density, positions=positions, far=np.inf, **kw)
    assert np.isfinite(out).all() and (out >= 0).all() and (out <= 1).all()
    if mode != "linear":
        np.testing.assert_allclose(out[:, 0], color[:, 0], atol=1e-6)           # distance 0: untouched
        sky = color[:, 4] if density == 0.0 else np.full((4, 3), 0.8)
        np.testing.assert_allclose(out[:, 4], sky, atol=1e-6)


@pytest.mark.parametrize("kwargs,message", [
    ({"mode": "fast"}, "FogSettings.mode must be one of linear, exp, exp2, hetero_exp, hetero_exp2"),
    ({"density": -0.1}, "FogSettings.density must be a finite number >= 0"),
    ({"density": float("nan")}, "FogSettings.density must be a finite number"),
    ({"mode": "linear", "start": 50.0, "end": 50.0}, "FogSettings.start must be < end for linear fog"),
    ({"color": np.zeros((3, 4, 4), np.float32)}, "color must be float32 (H, W, 3) = (3, 4, 3)"),
    ({"distance": np.zeros((3,), np.float32)}, "distance must be float32 (H, W)"),
    ({"distance": np.full((3, 4), -1.0, np.float32)}, "distance must be >= 0 metres or +inf"),
    ({"mode": "hetero_exp"}, "needs positions=(H, W, 3)"),
    ({"mode": "hetero_exp", "positions": np.zeros((3, 4, 2))}, "positions must be float32 (H, W, 3)"),
    ({"mode": "hetero_exp", "positions": np.zeros((3, 4, 3)), "octaves": 5}, "FogSettings.octaves must be a whole number 1..4"),
    ({"mode": "hetero_exp", "positions": np.zeros((3, 4, 3)), "noise": "cubic"}, "FogSettings.noise must be one of 'texture', 'procedural'"),
    ({"mode": "hetero_exp", "positions": np.zeros((3, 4, 3)), "resolutions": (512,)}, "FogSettings.resolutions must be 4 to 4 whole numbers"),
    ({"mode": "hetero_exp", "positions": np.zeros((3, 4, 3)), "resolutions": (8, 16, 32, 512)}, "FogSettings.resolutions[3] must be a whole number 2..256"),
    ({"sky": "paint"}, "FogSettings.sky must be one of 'fog', 'keep'"),
    ({"wobble": 1}, "unknown keyword(s) wobble"),
])
def test_bad_input_is_a_value_error_naming_what_is_allowed(gpu, ctx, kwargs, message):
    args = {"color": np.zeros((3, 4, 3), np.float32), "distance": np.ones((3, 4), np.float32)}
    args.update(kwargs)
    with pytest.raises(ValueError) as error:
        apply_fog(gpu, **args)
    assert message in str(error.value)


def test_plugin_configure_is_all_or_nothing():
    plugin = FogPlugin(mode="hetero_exp", density=0.06)
    with pytest.raises(ValueError, match="FogSettings.amplitude must be a finite number >= 0.0 and <= 1.0"):
        plugin.configure(density=0.01, amplitude=2.0)
    assert plugin.settings.density == 0.06 and plugin.settings.mode == "hetero_exp"
    assert FogPlugin(mode="heterogeneous_exp2").settings.mode == "hetero_exp2"


# -- the pass on a known depth buffer --------------------------------------------------------------
class KnownScene(RenderPass):
    """Writes given colour and depth values into the scene's textures."""
    name = "known_scene"
    phase = "opaque"

    def __init__(self, color, depth):
        self.color, self.depth = color, depth

    def setup(self, builder):
        builder.write(COLOR)
        builder.write(DEPTH)

    def execute(self, frame):
        frame.resource(COLOR).write(self.color.astype(np.float16).tobytes())
        frame.resource(DEPTH).write(self.depth.astype(np.float32).tobytes())


@pytest.mark.parametrize("mode,noise,sky,planes", [("exp", "texture", "fog", (0.5, 200.0)),
                                                   ("hetero_exp2", "procedural", "keep", (0.5, 200.0)),
                                                   ("hetero_exp", "texture", "fog", (0.5, 200.0)),
                                                   ("hetero_exp", "procedural", "fog", (0.1, 1e10))])
def test_fog_pass_on_a_known_depth_buffer_matches_reference(gpu, rng, mode, noise, sky, planes):
    w, h = 48, 27
    gpu = create_headless((w, h))
    try:
        near, far = planes
        cam = Camera(position=np.array([3.0, 8.0, 40.0]), near=near, far=far).look_at((0.0, 2.0, 0.0))
        color = np.dstack([rng.random((h, w, 3)), np.ones((h, w))])
        view_depth = rng.uniform(1.0, 150.0, (h, w))
        proj = cam.projection(w / h)
        ndc_z = (proj[2, 2] * -view_depth + proj[2, 3]) / view_depth
        depth = ndc_z * 0.5 + 0.5
        depth[:3, :] = 1.0                                   # sky rows
        settings = FogSettings(mode=mode, density=0.03, noise=noise, sky=sky, resolutions=SMALL,
                               tile_size=64.0, seed=int(rng.integers(2**32)))
        probe = CapturePass()
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False))
        app.graph.add_pass(KnownScene(color, depth))
        app.add_plugins(FogPlugin(settings))
        app.graph.add_pass(probe)
        app.insert_resource(cam)
        app.run_frames(1)
        assert gpu.ctx.error == "GL_NO_ERROR"
        # reference: distance and world position from the depth actually stored (rows bottom-up in GL)
        ys, xs = np.mgrid[0:h, 0:w]
        ndc = np.stack([(xs + 0.5) / w * 2 - 1, (ys + 0.5) / h * 2 - 1, probe.depth * 2 - 1, np.ones((h, w))], -1)
        p = ndc @ np.linalg.inv(cam.view_projection(w / h)).T
        world = p[..., :3] / p[..., 3:]
        distance = np.linalg.norm(world - cam.position, axis=-1)
        sky_px = probe.depth >= 1.0
        volumes = reference_volumes(settings) if noise == "texture" else None
        directions = (world - cam.position) / distance[..., None]
        distance = np.where(sky_px & (sky == "keep"), np.inf, distance)   # "fog": the far-plane point's
        ref = apply_fog_ref(color[..., :3].astype(np.float16).astype(np.float64), distance, settings, world,
                            app.clock.frame_time, volumes=volumes, directions=directions,
                            camera=cam.position, ground=True)
        np.testing.assert_allclose(probe.color[..., :3], ref, atol=4e-3, rtol=2e-3)
        assert np.abs(ref - color[..., :3]).mean() > 0.05
        app.close()
    finally:
        gpu.release()


def test_scene_without_fog_runs_and_compiles_none_of_it(gpu):
    gpu = create_headless((64, 36))
    try:
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), TerrainPlugin())
        app.run_frames(2)
        assert "fog" not in app.graph.dump().split()
        assert not any(f.startswith("fog/") for f in gpu.compiled_files)
        app.close()
    finally:
        gpu.release()


def test_terrain_is_about_ten_thousand_triangles_with_unit_normals():
    vertices, indices = heightfield()
    assert indices.size // 3 == TerrainPlugin().triangles == 10082
    np.testing.assert_allclose(np.linalg.norm(vertices[:, 3:], axis=1), 1.0, atol=1e-5)
    assert np.ptp(vertices[:, 1]) > 10.0


@pytest.mark.parametrize("preset", ["fig6", "valley"])
def test_fog_valley_demo_renders_fog_over_terrain(tmp_path, capsys, monkeypatch, preset):
    monkeypatch.setenv("ATMOS_FOG_PRESET", preset)
    path = tmp_path / "fog_valley.png"
    assert cli(["demo", "fog_valley", "--headless", "--frames", "2", "--size", "96x54", "--out", str(path),
                "--quiet"]) == 0
    from PIL import Image
    img = np.asarray(Image.open(path).convert("RGB")).astype(float)
    assert img.std() > 3.0                                       # not a flat picture
    assert img[-10:, :, 1].mean() > img[-10:, :, 0].mean()       # green terrain still shows near the camera
    assert img[:5].mean() > 150                                  # fogged sky is light


@pytest.mark.parametrize("color_from", ["fixed", "sky"])
def test_the_fog_scatters_sunlight_with_its_phase(gpu, ctx, rng, color_from):
    """sun_scattering > 0: the fog's colour gains Sun.color × sun_scattering × 4π p(θ): brightest toward
    the sun; the GPU matches the float64 reference; a set sun scatters none."""
    from atmos.lighting import Sun
    from atmos.plugins.fog.sky_color import SAMPLES, sun_angle
    color, distance, positions = random_inputs(rng)
    dirs = rng.normal(size=color.shape)
    dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    sun = Sun.from_angles(elevation_deg=float(rng.uniform(5, 60)), azimuth_deg=float(rng.uniform(0, 360)))
    if color_from == "sky":   # sqrt(1 - c) in float32 is ill-conditioned within ~1.5 degrees of the sun: no ray there
        while (near := (sun_angle(dirs, sun.direction) > 0.0) & (sun_angle(dirs, sun.direction) < 0.013)).any():
            dirs[near] = rng.normal(size=(int(near.sum()), 3))
            dirs /= np.linalg.norm(dirs, axis=-1, keepdims=True)
    dirs[2, 0] = sun.direction / np.linalg.norm(sun.direction)                  # one pixel looks at the sun
    distance[2] = 300.0                                                         # its row all as deep in fog
    horizon = rng.uniform(0.1, 1.0, (SAMPLES, 3)) if color_from == "sky" else None
    kw = dict(mode="exp", density=0.02, sun_scattering=0.3, color_from=color_from, horizon=horizon, directions=dirs)
    out = apply_fog(gpu, color, distance, sun=sun, **kw)
    settings = FogSettings(mode="exp", density=0.02, sun_scattering=0.3, color_from=color_from)
    ref = apply_fog_ref(color, distance, settings, directions=dirs, horizon=horizon, sun=sun)
    np.testing.assert_allclose(out, ref, atol=TOL)
    plain = apply_fog(gpu, color, distance, sun=sun, **{**kw, "sun_scattering": 0.0})   # the sky's colour follows the sun
    gain = (out - plain)[2].sum(-1)
    assert (out >= plain - 1e-6).all() and gain[0] > 3 * np.median(gain[1:]), "brightest toward the sun"
    night = Sun.from_angles(elevation_deg=-20.0, azimuth_deg=0.0)
    np.testing.assert_allclose(apply_fog(gpu, color, distance, sun=night, **kw),
                               apply_fog(gpu, color, distance, sun=night, **{**kw, "sun_scattering": 0.0}), atol=1e-6)
