"""Volumetric FBM fog: GPU FBM and march against the float64 reference, extremes, checks, the pass in a scene."""
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera
from atmos.froxels import froxel_jitter
from atmos.defaults import DefaultPlugins
from atmos.lighting import Sun
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.volumetric_fog import VolumetricFogSettings, VolumetricFogPlugin
from atmos import value_noise as noise
from atmos.plugins.volumetric_fog import reference
from atmos.plugins.volumetric_fog.noise import LATTICE, Lattice, filtered_error, noise_defines, noise_kind
from atmos.plugins.volumetric_fog.plugin import set_medium_uniforms, sun_terms
from atmos.render_core import CapturePass
from atmos.gpu.hazards import dispatch
from atmos.gpu.uniforms import bind_buffers, bind_textures, write_uniforms
from atmos.frame_constants import bind_frame

EPS32 = 2.0 ** -24


# -- GPU helpers -----------------------------------------------------------------------------------
def medium_program(gpu, shader, params, shadows=None):
    """``shader`` compiled for ``params``'s noise; the filtered noise's: the lattice of its seed bound
    (kept on ``gpu`` per seed). ``shadows``: a :class:`CloudShadowStub` the sunlight passes through."""
    defines = noise_defines(params, gpu)
    prog = gpu.program(compute_shader=shader, defines={**defines, "FOG_CLOUD_SHADOWS": 1} if shadows else defines)
    if shadows is not None:
        shadows.bind(prog)
    if noise_kind(params, gpu) != "filtered":
        return prog
    lattices = gpu.__dict__.setdefault("_test_fog_lattices", {})
    if params.seed not in lattices:
        lattices[params.seed] = Lattice(gpu)
        lattices[params.seed].sync(params.seed)
    bind_textures(prog, fog_lattice=lattices[params.seed].texture)
    return prog


def gpu_fbm(gpu, points, octaves, seed, kind=None):
    """value_fbm at ``points``; ``kind`` ("hash", "filtered"): the volumetric fog's lattice_fbm."""
    ctx = gpu.ctx
    if kind is None:
        prog = gpu.program(compute_shader="volumetric_fog/fbm_points.comp")
    else:
        prog = medium_program(gpu, "volumetric_fog/fbm_points.comp", VolumetricFogSettings(seed=seed, noise=kind))
    n = len(points)
    pts = np.zeros((n, 4), np.float32)
    pts[:, :3] = points
    src = ctx.buffer(pts.tobytes())
    dst = ctx.buffer(np.full(n, np.nan, np.float32).tobytes())
    try:
        bind_buffers(prog, Points=src, Values=dst)
        write_uniforms(prog, count=n, octaves=octaves, seed=seed)      # (the lattice's fbm has no seed uniform)
        dispatch(prog, -(-n // 64))
        return np.frombuffer(dst.read(), np.float32).astype(np.float64)
    finally:
        src.release(), dst.release()


def gpu_march(gpu, origins, dirs, limits, params, sun, time=0.0):
    ctx = gpu.ctx
    prog = medium_program(gpu, "volumetric_fog/march_rays.comp", params)
    n = len(origins)
    rays = np.zeros((n, 8), np.float32)
    rays[:, :3], rays[:, 3], rays[:, 4:7] = origins, limits, dirs
    src = ctx.buffer(rays.tobytes())
    dst = ctx.buffer(np.full((n, 4), np.nan, np.float32).tobytes())
    try:
        bind_buffers(prog, Rays=src, Results=dst)
        bind_frame(gpu, sun=sun)                      # the sun's direction: the frame block's
        set_medium_uniforms(prog, params, sun, time)
        prog["count"].value = n
        dispatch(prog, -(-n // 16))
        return np.frombuffer(dst.read(), np.float32).reshape(n, 4).astype(np.float64)
    finally:
        src.release(), dst.release()


def ref_march(origins, dirs, limits, params, sun, time=0.0):
    s, sun_light, ambient_light = sun_terms(sun, params)
    return reference.march(origins, dirs, limits, params, s, sun_light, ambient_light, time)


def fbm_tolerance(points, octaves):
    """Float32 error bound: octave i sees coordinates |p|·Π(2+k/10); its noise (slope <= 1.5 per axis)
    moves by at most 2^-(i+1)·min(1, 6·|coord|·eps32), plus rounding of the sum."""
    mag = np.abs(points).max(axis=-1) + 1.0
    tol = np.full(len(points), 1e-6)
    growth = 1.0
    for i in range(octaves):
        tol += 0.5 ** (i + 1) * np.minimum(1.0, 6.0 * mag * growth * 4 * EPS32)
        growth *= 2.0 + i / 10.0
    return tol


def filtered_tolerance(params, sun, gpu):
    """What the filtered noise may add to a march's (light rgb, T) error: the density off by at most
    δ = filtered_error(octaves), so the optical depth along the view ray (at most the envelope's diameter,
    or max_distance) by Δτ = absorption·δ·length and toward the sun by absorption·δ·light_steps·light_step;
    T moves by at most Δτ, the light by at most twice Δτ times its largest source (ambient + sun) plus the
    sunlight times the sun's Δτ. Zero for the hashed noise (``gpu``: where "auto" is resolved)."""
    if noise_kind(params, gpu) == "hash":
        return np.zeros(4)
    _, sun_light, ambient_light = sun_terms(sun, params)
    delta = params.absorption * filtered_error(params.octaves)
    radius = (params.bias + 1.0) / params.falloff if params.falloff > 0 else math.inf
    view = delta * min(2.0 * radius * max(params.scale), params.max_distance)
    toward_sun = delta * params.light_steps * params.light_step
    sun_max, ambient_max = np.abs(sun_light).max(), np.abs(ambient_light).max()
    return np.array([2.0 * view * (ambient_max + sun_max) + sun_max * toward_sun] * 3 + [view])


# -- FBM ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("octaves", [1, 3, 8, 16])
def test_gpu_fbm_matches_float64_reference(gpu, ctx, rng, octaves):
    n = 4096
    points = rng.uniform(-60, 60, (n, 3)) * rng.choice([0.01, 0.1, 1.0], (n, 1))
    points = points.astype(np.float32).astype(np.float64)        # the GPU sees float32 inputs
    seed = int(rng.integers(0, 2**32))
    got = gpu_fbm(gpu, points, octaves, seed)
    want = noise.fbm(points, octaves, seed)
    assert np.isfinite(got).all(), "every output written"
    err = np.abs(got - want)
    tol = fbm_tolerance(points, octaves)
    assert (err <= tol).all(), f"max error {err.max():.3g}, worst excess {(err - tol).max():.3g}"
    assert got.std() > 0.03, "noise is not flat"
    assert (want >= 0).all() and (want < 1 - 2.0 ** -octaves).all()


def test_noise_at_lattice_points_equals_hash_exactly(gpu, ctx, rng):
    cells = rng.integers(-10**6, 10**6, (1024, 3)).astype(np.float64)
    seed = int(rng.integers(0, 2**32))
    got = gpu_fbm(gpu, cells, 1, seed)
    assert np.array_equal(got, 0.5 * noise.lattice(cells.astype(np.int64), noise.key(seed)))


def test_the_baked_lattice_is_the_hashed_one_and_follows_the_seed(gpu, ctx, rng):
    seed = int(rng.integers(0, 2**32))
    lattice = Lattice(gpu)
    try:
        texture = lattice.sync(seed)
        cells = np.stack(np.meshgrid(*[np.arange(LATTICE)] * 3, indexing="ij"), -1)
        assert np.array_equal(lattice.read(), noise.lattice(cells, noise.key(seed)).astype(np.float32))
        assert lattice.sync(seed) is texture and lattice.seed == seed
        lattice.sync(seed ^ 1)
        assert np.array_equal(lattice.read(), noise.lattice(cells, noise.key(seed ^ 1)).astype(np.float32))
        far = rng.integers(-10**6, 10**6, (64, 3))                 # the lattice repeats every LATTICE cells
        assert np.array_equal(noise.lattice(far, 5, LATTICE), noise.lattice(far % LATTICE, 5))
    finally:
        lattice.release()


@pytest.mark.parametrize("kind", ["hash", "filtered"])
def test_the_fogs_fbm_matches_float64_reference(gpu, ctx, rng, kind):
    """lattice_fbm: hashed within float32 rounding of the float64 FBM on the repeating lattice, from the
    baked texture within that plus filtered_error (the texture unit's weights)."""
    n, octaves = 4096, 6
    points = rng.uniform(-300, 300, (n, 3)) * rng.choice([0.01, 0.1, 1.0], (n, 1))
    points = points.astype(np.float32).astype(np.float64)
    seed = int(rng.integers(0, 2**32))
    got = gpu_fbm(gpu, points, octaves, seed, kind)
    want = noise.fbm(points, octaves, seed, LATTICE)
    tol = fbm_tolerance(points, octaves) + (filtered_error(octaves) if kind == "filtered" else 0.0)
    err = np.abs(got - want)
    assert np.isfinite(got).all() and (err <= tol).all(), f"max error {err.max():.3g}, worst excess {(err - tol).max():.3g}"
    assert got.std() > 0.03, "noise is not flat"
    if kind == "hash":
        assert np.median(err) < 1e-5


def test_value_noise_is_smooth_and_in_range(rng):
    k = noise.key(7)
    x = rng.uniform(-5, 5, (2000, 3))
    v = noise.value_noise(x, k)
    assert (v >= 0).all() and (v < 1).all()
    h = 1e-6                                            # continuous with slope <= 1.5 per axis
    for axis in range(3):
        dx = np.zeros(3)
        dx[axis] = h
        assert np.abs(noise.value_noise(x + dx, k) - v).max() <= 1.5 * h * 1.0001


def test_fbm_extreme_inputs_stay_finite_and_in_range(gpu, ctx):
    points = np.array([[0, 0, 0], [1e6, -1e6, 1e6], [-3e7, 2e7, 1e7], [1e9, 1e9, -1e9],
                       [3.4e38, -3.4e38, 1.0], [1e-30, -1e-30, 0]], np.float64)
    for octaves in (1, 16):
        got = gpu_fbm(gpu, points, octaves, 123)
        assert np.isfinite(got).all() and (got >= 0).all() and (got < 1).all(), got
    ref = noise.fbm(points, 16, 123)
    assert np.isfinite(ref).all() and (ref >= 0).all() and (ref < 1).all()


def test_octave_rotation_is_orthonormal():
    assert np.allclose(noise.ROTATION @ noise.ROTATION.T, np.eye(3))


# -- the march ---------------------------------------------------------------------------------------
def random_rays(rng, n, params, spread=1.5):
    radius = (params.bias + 1) / params.falloff if params.falloff > 0 else 30.0
    origins = np.asarray(params.center) + rng.uniform(-spread, spread, (n, 3)) * radius * np.asarray(params.scale)
    targets = np.asarray(params.center) + rng.uniform(-0.4, 0.4, (n, 3)) * radius * np.asarray(params.scale)
    dirs = np.where(rng.random((n, 1)) < 0.7, targets - origins, rng.normal(size=(n, 3)))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    limits = np.where(rng.random(n) < 0.3, rng.uniform(1, 80, n), 1e30)
    return (origins.astype(np.float32).astype(np.float64), dirs.astype(np.float32).astype(np.float64),
            limits.astype(np.float32).astype(np.float64))


@pytest.mark.parametrize("kind", ["hash", "filtered"])
def test_gpu_march_matches_float64_reference(gpu, ctx, rng, kind):
    params = VolumetricFogSettings(center=tuple(rng.uniform(-5, 5, 3)), scale=(1.5, 0.6, 1.2), bias=0.1, falloff=0.05,
                       frequency=float(rng.uniform(0.1, 0.3)), octaves=5, seed=int(rng.integers(0, 2**32)),
                       wind=(1.0, 0.0, -0.5), absorption=float(rng.uniform(0.1, 0.4)), steps=40,
                       light_steps=4, light_step=2.5, max_distance=150.0, noise=kind)
    sun = Sun.from_angles(float(rng.uniform(10, 70)), float(rng.uniform(0, 360)))
    origins, dirs, limits = random_rays(rng, 256, params)
    got = gpu_march(gpu, origins, dirs, limits, params, sun, time=1.25)
    want = ref_march(origins, dirs, limits, params, sun, time=1.25)
    assert np.isfinite(got).all(), "every ray written"
    assert (want[:, 3] < 0.9).sum() > 20 and (want[:, 3] > 0.999).sum() > 5, "rays both through and past the fog"
    # float32 noise can flip an early exit (T or Tl near 0.01): the skipped tail is <= 1% of the light
    tol = 2e-3 + 1.5e-2 * np.abs(want).max(axis=0) + filtered_tolerance(params, sun, gpu)
    err = np.abs(got - want)
    assert (err <= tol).all(), f"max error {err.max(axis=0)} > {tol}"
    assert np.median(err[:, :3]) < (1e-4 if kind == "hash" else 2e-3)


def test_march_converges_with_steps_and_exits_early():
    params = VolumetricFogSettings(center=(0, 0, 0), scale=(1, 1, 1), octaves=4, absorption=0.2, light_steps=2)
    sun = Sun.from_angles(40)
    o, d, lim = np.array([[0.0, 0.0, -40.0]]), np.array([[0.0, 0.0, 1.0]]), np.array([1e30])
    ref = ref_march(o, d, lim, params.replace(steps=1024), sun)
    errs = [np.abs(ref_march(o, d, lim, params.replace(steps=s), sun) - ref).max() for s in (8, 32, 128)]
    assert errs[2] < errs[0] and errs[2] < 0.02
    thick = ref_march(o, d, lim, params.replace(absorption=50.0, steps=256), sun)
    assert 0 < thick[0, 3] <= 0.01 and np.isfinite(thick).all()


@pytest.mark.parametrize("change", [
    dict(absorption=0.0), dict(absorption=1e4), dict(steps=1), dict(steps=1024, octaves=2),
    dict(light_steps=0), dict(falloff=0.0, max_distance=60.0), dict(bias=-5.0), dict(octaves=16, steps=8),
    dict(frequency=1e3), dict(max_distance=1e-3)])
def test_march_extremes_finite_and_as_reference(gpu, ctx, rng, change):
    params = VolumetricFogSettings(center=(0, 0, 0), scale=(1, 1, 1), octaves=3, steps=16, light_steps=3,
                                   noise="hash").replace(**change)
    origins = np.array([[0.0, 0.0, 0.0], [0.0, 5.0, -60.0], [1e3, 0, 0], [0.0, 0.0, -25.0]])
    dirs = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0, 0], [0.0, 0.0, 1.0]])
    limits = np.array([1e30, 1e30, 2e3, 0.0])
    for sun in (Sun.from_angles(45), Sun.from_angles(-60), Sun.from_angles(0.0)):   # (a zero Sun is refused)
        got = gpu_march(gpu, origins, dirs, limits, params, sun)
        want = ref_march(origins, dirs, limits, params, sun)
        assert np.isfinite(got).all() and (got >= 0).all() and (got[:, 3] <= 1).all()
        assert np.allclose(got[3], [0, 0, 0, 1]), "zero-length ray: no fog"
        if change.get("frequency", 0) < 100 and change.get("octaves", 3) < 16:
            assert np.allclose(got, want, atol=3e-3 + 1.5e-2 * np.abs(want).max()), (got, want)
    if params.absorption == 0 or params.bias == -5.0:
        assert np.array_equal(got, np.tile([0, 0, 0, 1.0], (4, 1)))


# -- parameters ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("change, message", [
    (dict(octaves=0), "VolumetricFogSettings.octaves must be a whole number 1..16, got 0"),
    (dict(octaves=17), "1..16"), (dict(octaves=2.5), "whole number"), (dict(octaves=True), "whole number"),
    (dict(steps=0), "VolumetricFogSettings.steps must be a whole number 1..1024"), (dict(steps=2000), "1..1024"),
    (dict(light_steps=-1), "0..32"), (dict(froxels=(0, 4, 4)), "froxels must be None or three ints in \\[1, 256\\]"),
    (dict(froxels=(8, 8)), "froxels must be None or three ints"), (dict(light_step=0), "light_step must be a finite number > 0"), (dict(absorption=-1), "VolumetricFogSettings.absorption must be a finite number >= 0"),
    (dict(absorption=math.nan), "absorption"), (dict(frequency=0), "frequency must be a finite number > 0"),
    (dict(scale=(1, 0, 1)), "VolumetricFogSettings.scale must be 3 positive numbers"), (dict(center=(1, 2)), "center"),
    (dict(ambient=(-1, 0, 0)), "non-negative"), (dict(max_distance=math.inf), "max_distance"),
    (dict(seed=-1), "0..4294967295"), (dict(colour=(1, 1, 1)), "unknown VolumetricFogSettings setting(s) colour; known:"),
])
def test_bad_settings_are_refused_and_nothing_is_applied(change, message):
    plugin = VolumetricFogPlugin(steps=20)
    before = plugin.settings
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)").replace(".", r"\.")):
        plugin.configure(**{"light_step": 0.5, **change})
    assert plugin.settings is before
    with pytest.raises(ValueError):
        VolumetricFogPlugin(**change)


# -- the pass in a scene --------------------------------------------------------------------------------
def render(gpu, *plugins, camera_at=(0.0, 6.0, 45.0), target=(0.0, 2.0, 0.0)):
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), GroundPlugin(), *plugins)
    app.insert_resource(Sun.from_angles(30.0, 60.0))
    cam = app.resource(Camera)
    cam.position = np.array(camera_at)
    cam.look_at(target)
    capture = app.graph.add_pass(CapturePass())
    app.run_frames(1)
    app.close()
    return capture, cam


def test_pass_blends_the_reference_march_over_the_scene_stopping_at_depth(fresh_gpu, tmp_path):
    params = VolumetricFogSettings(octaves=4, steps=24, light_steps=3, absorption=0.15)
    bg, cam = render(fresh_gpu)
    fog, _ = render(fresh_gpu, VolumetricFogPlugin(params, animate=False))
    assert np.isfinite(fog.color).all()
    save_png(tmp_path, "fog_pass.png", fog.color)
    h, w = fog.depth.shape
    ys, xs = np.meshgrid(np.arange(0, h, 3), np.arange(0, w, 3), indexing="ij")
    ys, xs = ys.ravel(), xs.ravel()
    inv = np.linalg.inv(cam.view_projection(w / h))
    ndc = np.stack([(xs + 0.5) / w * 2 - 1, (ys + 0.5) / h * 2 - 1], axis=1)   # row 0 is the bottom
    far = (inv @ np.c_[ndc, np.ones(len(xs)), np.ones(len(xs))].T).T
    dirs = far[:, :3] / far[:, 3:] - cam.position
    z = bg.depth[ys, xs]
    hit = (inv @ np.c_[ndc, z * 2 - 1, np.ones(len(xs))].T).T
    limits = np.where(z >= 1, 1e30, np.linalg.norm(hit[:, :3] / hit[:, 3:] - cam.position, axis=1))
    march = ref_march(np.tile(cam.position, (len(xs), 1)), dirs, limits, params, Sun.from_angles(30.0, 60.0))
    want = march[:, :3] + march[:, 3:] * bg.color[ys, xs, :3]
    got = fog.color[ys, xs, :3]
    assert (z < 1).sum() > 10 and (z >= 1).sum() > 10, "ground and sky pixels both tested"
    assert (march[:, 3] < 0.8).sum() > 10, "the fog is visible"
    tol = 4e-3 + filtered_tolerance(params, Sun.from_angles(30.0, 60.0), fresh_gpu)[:3]   # the default noise
    assert np.allclose(got, want, atol=tol, rtol=2e-2), np.abs(got - want).max()


def save_png(folder, name, hdr):
    from PIL import Image
    img = np.clip(hdr[::-1, :, :3] / (1 + hdr[::-1, :, :3]), 0, 1) ** (1 / 2.2)
    Image.fromarray((img * 255).astype(np.uint8)).save(folder / name)


def test_scene_without_fog_compiles_and_runs_none_of_it(fresh_gpu):
    app = App(fresh_gpu).add_plugins(DefaultPlugins(overlay=False), GroundPlugin())
    app.run_frames(2)
    assert "volumetric_fog" not in app.graph.dump()
    assert not any(f.startswith("volumetric_fog/") for f in fresh_gpu.compiled_files)
    app.close()


def test_volumetric_fog_demo_runs_headless(tmp_path, capsys):
    from PIL import Image
    from atmos.cli import main
    out = tmp_path / "fog"
    assert main(["demo", "volumetric_fog", "--headless", "--frames", "3", "--size", "64x36",
                 "--out", str(out), "--quiet"]) == 0
    img = np.asarray(Image.open(out / "frame_00002.png"), float)
    assert img.std() > 5, "not a blank frame"


def test_the_fog_can_take_its_ambient_light_from_the_sky():
    """ambient_from="sky": the ambient is the App's sky's mean horizon radiance: the night sky's glow at
    night (darker than the fixed ambient's tenth), warmer at dawn than at noon; the pass renders with
    it; without a sky it is a clear error."""
    from types import SimpleNamespace
    from atmos.gpu import create_headless
    from atmos.plugins.sky import SkyPlugin
    gpu = create_headless((48, 27))
    try:
        fog = VolumetricFogPlugin(ambient_from="sky", ambient=(1.0, 1.0, 1.0))
        app = App(gpu).add_plugins(DefaultPlugins(), SkyPlugin(), GroundPlugin(), fog)
        app.run_frames(2)
        cam = app.resource(Camera)
        light = {name: fog.sky_ambient(SimpleNamespace(sun=Sun.from_angles(elevation_deg=e, azimuth_deg=90.0), camera=cam))
                 for name, e in (("noon", 60.0), ("dawn", 2.0), ("night", -20.0))}
        assert all(np.isfinite(v).all() and (v >= 0).all() for v in light.values())
        assert light["night"].sum() < 0.1 * light["noon"].sum()           # the night sky's faint glow
        fixed_night = sun_terms(Sun.from_angles(elevation_deg=-20.0, azimuth_deg=90.0), VolumetricFogSettings())[2]
        assert light["night"].sum() < 0.5 * fixed_night.sum()
        assert light["dawn"][0] / light["dawn"][2] > 1.2 * light["noon"][0] / light["noon"][2]    # warmer at dawn
        assert gpu.ctx.error == "GL_NO_ERROR" and np.isfinite(gpu.read_pixels()).all()
        app.close()
        bare = App(gpu).add_plugins(DefaultPlugins(), GroundPlugin(), VolumetricFogPlugin(ambient_from="sky"))
        with pytest.raises(ValueError, match="ambient_from='sky' takes the light of the App's sky"):
            bare.run_frames(1)
        bare.close()
    finally:
        gpu.release()


# -- the froxel volume (VolumetricFogSettings.froxels) ------------------------------------------------
class CloudShadowStub:
    """A cloud shadow map of random columns (rg16f) over a layer above the fog, as the bake would lay it out
    for ``camera`` and ``sun``: bound to a program, and its float64 optical depth (``tau``)."""

    def __init__(self, gpu, rng, params, camera, sun):
        import moderngl
        from atmos.lighting import unit_sun
        from atmos.plugins.clouds.shadows.shadow_map import shadow_space
        from atmos.plugins.clouds.volume.layout import CloudLayout
        centre = np.asarray(params.center, np.float64)
        self.sun = unit_sun(sun.direction)
        shape, cell = (16, 4, 16), (6.0, 3.0, 6.0)
        layout = CloudLayout(shape, cell, ((centre[0] - 48.0) / 6.0, (centre[2] - 48.0) / 6.0), 60.0, (8, 8), 0.0)   # over the fog
        self.space = shadow_space(layout, camera.position, self.sun, 400.0, size=64)
        n = self.space.size
        self.map = rng.uniform(0.0, 4.0, (2 * n, n, 2)).astype(np.float16).astype(np.float64)
        self.weights = (float(rng.uniform(0.2, 1.0)), float(rng.uniform(0.0, 0.5)))
        self.texture = gpu.ctx.texture((n, 2 * n), 2, self.map.astype(np.float16).tobytes(), dtype="f2")
        self.texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self.texture.repeat_x = self.texture.repeat_y = False

    def bind(self, program) -> None:
        bind_textures(program, cloud_shadow_map=self.texture)
        self.space.uniforms(program, *self.weights)

    def tau(self, points) -> np.ndarray:
        from atmos.plugins.clouds.shadows.shadow_map import lookup_reference
        return lookup_reference(self.space, self.map, points, self.sun, self.weights)


def gpu_froxels(gpu, camera, aspect, froxels, params, sun, time=0.0, frame=None, shadows=None):
    """(W, H, D + 1, 4): volumetric_fog/froxels.comp for ``camera``, its slices sampled at the middles or at
    froxel_jitter of ``frame`` (read back as float64); ``shadows``: a CloudShadowStub."""
    from atmos.gpu.uniforms import bind_images, write_uniforms
    from atmos.froxels import froxel_knee
    w, h, d = froxels
    prog = medium_program(gpu, "volumetric_fog/froxels.comp", params, shadows)
    volume = gpu.ctx.texture3d((w, h, d + 1), 4, dtype="f2")
    try:
        bind_frame(gpu, camera, sun, (aspect, 1.0), frame_index=frame or 0)     # camera (its aspect), sun, frame
        set_medium_uniforms(prog, params, sun, time)
        write_uniforms(prog, froxel_knee=froxel_knee(params.max_distance), froxel_jittered=int(frame is not None))
        bind_images(prog, fog_volume=volume)
        dispatch(prog, -(-w // 8), -(-h // 8))
        data = np.frombuffer(volume.read(), np.float16).astype(np.float64)
        return data.reshape(d + 1, h, w, 4).transpose(2, 1, 0, 3)
    finally:
        volume.release()


def ref_froxels(camera, aspect, froxels, params, sun, time=0.0, jitter=0.5, shadows=None):
    from atmos.camera import view_basis
    from atmos.froxels import froxel_knee
    s, sun_light, ambient_light = sun_terms(sun, params)
    return reference.froxel_volume(camera.position, view_basis(camera, aspect), froxels, params, s, sun_light,
                                   ambient_light, froxel_knee(params.max_distance), time, jitter,
                                   None if shadows is None else shadows.tau)


def froxel_camera(rng, params):
    cam = Camera()
    radius = (params.bias + 1) / params.falloff
    cam.position = np.asarray(params.center) + np.array([rng.uniform(-1, 1), 0.3, 1.6]) * radius * np.asarray(params.scale)
    cam.look_at(tuple(np.asarray(params.center) + rng.uniform(-0.2, 0.2, 3) * radius))
    return cam


@pytest.mark.parametrize("clouds", [False, True])
def test_gpu_froxel_volume_matches_its_float64_twin(gpu, ctx, rng, clouds):
    """froxels.comp against reference.froxel_volume; ``clouds``: the sunlight through a random cloud
    shadow map (FOG_CLOUD_SHADOWS), τ from lookup_reference on the same map."""
    params = VolumetricFogSettings(center=tuple(rng.uniform(-5, 5, 3)), scale=(1.5, 0.6, 1.2), bias=0.1, falloff=0.05,
                                   frequency=float(rng.uniform(0.1, 0.3)), octaves=5, seed=int(rng.integers(0, 2**32)),
                                   absorption=float(rng.uniform(0.1, 0.4)), light_steps=4, light_step=2.5,
                                   max_distance=150.0, froxels=(24, 14, 40), noise="hash")
    sun = Sun.from_angles(float(rng.uniform(10, 70)), float(rng.uniform(0, 360)))
    cam = froxel_camera(rng, params)
    index = int(rng.integers(0, 2**32))           # the frame: where in each slice the sample lies (froxel_jitter)
    shadows = CloudShadowStub(gpu, rng, params, cam, sun) if clouds else None
    got = gpu_froxels(gpu, cam, 16 / 9, params.froxels, params, sun, time=0.75, frame=index, shadows=shadows)
    want = ref_froxels(cam, 16 / 9, params.froxels, params, sun, time=0.75, jitter=froxel_jitter(index), shadows=shadows)
    if clouds:
        bare = ref_froxels(cam, 16 / 9, params.froxels, params, sun, time=0.75, jitter=froxel_jitter(index))
        top = np.abs(bare[..., :3]).max()
        lit = bare[..., :3].max(-1) > 0.1 * top
        assert (np.abs(bare - want)[..., :3].max(-1)[lit] > 0.05 * top).mean() > 0.3, "the clouds shadow the fog"
    assert np.isfinite(got).all() and got.shape == want.shape == (24, 14, 41, 4)
    assert (want[..., -1, 3] < 0.9).sum() >= 10 and (want[..., -1, 3] > 0.999).sum() >= 5, "columns in and past the fog"
    assert np.allclose(got[:, :, 0], [0, 0, 0, 1]), "layer 0 is the camera"
    # the march's float32 tolerance (early exits at 0.01 may flip) plus float16 storage (2^-11 relative)
    tol = 2e-3 + 1.5e-2 * np.abs(want).max(axis=(0, 1, 2)) + 2.0 ** -11 * np.abs(want)
    err = np.abs(got - want)
    assert (err <= tol).all(), f"max error {err.max(axis=(0, 1, 2))}"
    assert np.median(err[..., :3]) < 2e-4


def test_froxels_converge_to_the_per_pixel_march_with_slices():
    params = VolumetricFogSettings(center=(0, 0, 0), scale=(1.5, 0.6, 1.2), octaves=4, absorption=0.2, light_steps=3,
                                   max_distance=120.0)
    sun = Sun.from_angles(35, 40)
    cam = Camera()
    cam.position = np.array([6.0, 2.0, 40.0])
    cam.look_at((0.0, 0.0, 0.0))
    from atmos.camera import view_basis
    from atmos.froxels import froxel_knee, froxel_lookup
    w, h = 12, 8
    uv = np.stack(np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h, indexing="ij"), -1).reshape(-1, 2)
    rays = np.c_[uv * 2 - 1, np.ones(len(uv))] @ view_basis(cam, 1.5).T
    dists = np.linspace(5.0, 200.0, len(uv))                   # scene distances from near to beyond the fog
    exact = ref_march(np.tile(cam.position, (len(uv), 1)), rays, dists, params.replace(steps=256), sun)
    errors = []
    for slices in (8, 32, 128):
        volume = ref_froxels(cam, 1.5, (w, h, slices), params, sun)
        got = froxel_lookup(volume, uv, dists, params.max_distance, froxel_knee(params.max_distance))
        errors.append(np.abs(got - exact).max())
    assert errors[0] > errors[1] > errors[2] and errors[2] < 0.25 * errors[0], errors
    assert errors[2] < 0.02


def test_a_scene_with_froxel_fog_is_the_twin_read_at_each_pixel(fresh_gpu):
    from atmos.camera import view_basis
    from atmos.froxels import froxel_knee, froxel_lookup
    params = VolumetricFogSettings(octaves=4, light_steps=3, absorption=0.15, froxels=(32, 18, 48), animate=False)
    bg, cam = render(fresh_gpu)
    fog, _ = render(fresh_gpu, VolumetricFogPlugin(params))
    h, w = fog.depth.shape
    ys, xs = np.meshgrid(np.arange(0, h, 3), np.arange(0, w, 3), indexing="ij")
    ys, xs = ys.ravel(), xs.ravel()
    uv = np.c_[(xs + 0.5) / w, (ys + 0.5) / h]
    rays = np.c_[uv * 2 - 1, np.ones(len(uv))] @ view_basis(cam, w / h).T
    z = bg.depth[ys, xs].astype(np.float64)
    view_z = cam.near / ((1 - z) + z * cam.near / cam.far)
    dists = np.where(z >= 1, 1e30, view_z * np.linalg.norm(rays, axis=1))
    volume = ref_froxels(cam, w / h, params.froxels, params, Sun.from_angles(30.0, 60.0))
    medium = froxel_lookup(volume, uv, dists, params.max_distance, froxel_knee(params.max_distance))
    want = medium[:, :3] + medium[:, 3:] * bg.color[ys, xs, :3]
    got = fog.color[ys, xs, :3]
    assert (medium[:, 3] < 0.8).sum() > 10, "the fog is visible"
    # float16 volume and colour, float32 noise; filter weights: 1/256 of the neighbours' spread on any GPU
    spread = np.abs(np.diff(volume, axis=2)).max() / 256
    tol = 4e-3 + spread + filtered_tolerance(params, Sun.from_angles(30.0, 60.0), fresh_gpu)[:3]   # the default noise
    assert np.allclose(got, want, atol=tol, rtol=2e-2), np.abs(got - want).max()


def test_the_fogs_sunlight_passes_through_the_clouds_shadow_map(gpu, ctx, rng):
    """With clouds in the scene the sunlight of each fog sample is its own light march's times the clouds'
    exp(−τ) from the cloud shadow map: the per-pixel pass against the float64 march whose τ is
    lookup_reference on the GPU's own map (random column sums); the froxel volume darkens likewise, and
    ``cloud_shadows=False`` gives the unshadowed fog back."""
    from atmos.plugins.clouds import CloudSettings, CloudSimulation, CloudsPlugin
    from atmos.plugins.clouds.shadows.shadow_map import lookup_reference
    from atmos.plugins.clouds.weather import VolumeOrigin
    from atmos.lighting import unit_sun
    from test_cloud_shadow_map import MapCapture
    from test_cloud_shadows import FillPass, pass_plugin, ray_dirs, weather, write_sums
    fill, probe, capture = FillPass(), CapturePass(), MapCapture()
    clouds = CloudsPlugin(CloudSettings(smoothing_slices=2, group_size=(8, 8), shading=False, cell_size=(6.0, 2.0, 6.0)),
                          weather=weather(), seed=5)
    fog = VolumetricFogPlugin(VolumetricFogSettings(scale=(3.0, 0.5, 3.0), bias=0.3, falloff=0.05, frequency=0.05,
                                                    octaves=3, absorption=0.05, steps=32, light_steps=2, light_step=2.0,
                                                    max_distance=600.0, ambient=(0.0, 0.0, 0.0),
                                                    scattering=(1.0, 1.0, 1.0), animate=False, noise="hash"))
    app = App(gpu).insert_resource(VolumeOrigin(0.0, 0.0, 0.0))
    app.add_plugins(DefaultPlugins(overlay=False), clouds, pass_plugin(fill), fog, pass_plugin(probe), pass_plugin(capture))
    app.startup()
    sim = app.resource(CloudSimulation)
    for _ in range(2):
        app.update(1 / 30)
    a, b, _ = sim.view()
    nx, ny, nz = sim.shape
    for s in (a, b):
        write_sums(sim, s, rng.uniform(0, ny, (1 + sim.maps_of(s).bands, nx, nz)))
    layout = sim.sets().layout()
    sun = Sun.from_angles(float(rng.uniform(30, 70)), float(rng.uniform(0, 360)))
    app.insert_resource(sun)
    s = unit_sun(sun.direction)
    centre = layout.lo + 0.5 * (layout.hi - layout.lo)
    shadow = centre - s * centre[1] / s[1]                   # where the layer's shadow falls on the ground
    shadow[1] = 6.0
    fog.configure(center=tuple(shadow))
    cam = app.resource(Camera)
    cam.near, cam.far = 1.0, 1000.0
    cam.position = shadow + np.array([rng.uniform(-160, -120), rng.uniform(50, 90), rng.uniform(-30, 30)])
    cam.look_at(shadow)
    size = gpu.size
    fill.color, fill.depth = np.zeros((size[1], size[0], 4)), np.ones((size[1], size[0]))
    app.render()                                # render only: the sets stay as written
    got = probe.color[..., :3].reshape(-1, 3)
    params = fog.settings
    s_dir, sun_light, ambient_light = sun_terms(sun, params)
    dirs = ray_dirs(cam, size).reshape(-1, 3)
    origins = np.broadcast_to(cam.position, dirs.shape)
    sigma = float(sim.settings.sigma)
    tau = lambda p: lookup_reference(capture.space, capture.map, p, s, (sigma, 0.0))
    want = reference.march(origins, dirs, np.full(len(dirs), 1e30), params, s_dir, sun_light, ambient_light, 0.0, tau)
    bare = reference.march(origins, dirs, np.full(len(dirs), 1e30), params, s_dir, sun_light, ambient_light, 0.0)
    tol = 4e-3 + 2e-2 * np.abs(want[:, :3])      # f16 colour, float32 noise's early exits (as the pass's test)
    assert np.isfinite(got).all()
    assert np.all(np.abs(got - want[:, :3]) <= tol), f"max error {np.abs(got - want[:, :3]).max()}"
    shaded = np.abs(bare[:, :3] - want[:, :3]).max(-1) > 10 * tol.max(-1)
    assert shaded.sum() > 100, "the clouds' shadows fall through the fog"
    fog.configure(froxels=(32, 18, 32), froxel_history=1.0)
    app.render()
    froxel = probe.color[..., :3].mean()
    fog.configure(cloud_shadows=False)
    app.render()
    assert froxel < 0.9 * probe.color[..., :3].mean(), "the froxels' fog is shadowed too"
    fog.configure(froxels=None)
    app.render()
    assert np.all(np.abs(probe.color[..., :3].reshape(-1, 3) - bare[:, :3]) <= 4e-3 + 2e-2 * np.abs(bare[:, :3]))
    app.close()
