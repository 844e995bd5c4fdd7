"""2D cloud layer: tiling octaves and shading against the float64 reference, the pass in a scene, checks."""
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.lighting import Sun
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_layer import SkyLayerSettings, SkyLayerPlugin, reference
from atmos.tile_octaves import OctaveTextures
from atmos.plugins.sky_layer.plugin import layer_light, scroll_offsets
from atmos.render_core import CapturePass
from atmos.gpu.uniforms import bind_buffers


# -- octave textures ---------------------------------------------------------------------------------
def test_gpu_octaves_match_reference_and_every_texel_is_written(gpu, ctx, rng):
    params = SkyLayerSettings(size=48, base_frequency=int(rng.integers(3, 8)), seed=int(rng.integers(0, 2**32)),
                            light_step=float(rng.uniform(0.005, 0.05)))
    sun = Sun.from_angles(float(rng.uniform(5, 80)), float(rng.uniform(0, 360))).direction
    octaves = OctaveTextures(gpu)
    try:
        octaves.bake(params, sun)
        for tex in octaves.textures:
            tex.write(np.full((48, 48, 4), np.nan, np.float32).tobytes())
        octaves.bake(params, sun)
        shift = reference.light_shift(sun, params.light_step)
        assert np.isclose(np.linalg.norm(shift), params.light_step)
        for k in range(4):
            got = octaves.download(k)
            want = reference.octave_texture(48, params.base_frequency * 2 ** k,
                                            reference.octave_key(params.seed, k), shift)
            assert np.isfinite(got).all(), f"octave {k}: every texel written"
            assert np.abs(got - want).max() < 2e-4 * 2 ** k, f"octave {k}: {np.abs(got - want).max()}"
            assert got.std() > 0.03
        assert octaves.bakes == 2
        steps = (0.0, 2.0, -2.0, 0.5)               # the far field's relief channels: toward and away from the sun
        octaves.bake(params, sun, steps=steps)
        want = reference.octave_texture(48, params.base_frequency, reference.octave_key(params.seed, 0), shift, steps)
        assert np.abs(octaves.download(0) - want).max() < 2e-4
    finally:
        octaves.release()


def test_octaves_tile_seamlessly(rng):
    k = reference.octave_key(int(rng.integers(0, 2**32)), 1)
    uv = rng.random((500, 2))
    for shift in ([1, 0], [0, 1], [1, 1], [-2, 3]):
        assert np.allclose(reference.tile_noise(uv + shift, 8, k), reference.tile_noise(uv, 8, k), atol=1e-12)
    tex = reference.octave_texture(64, 8, k, (0.0, 0.0))[..., 0]
    inner = np.abs(np.diff(tex, axis=0)).max()          # steps between neighbours inside the tile
    assert np.abs(tex[0] - tex[-1]).max() <= inner * 1.01 and np.abs(tex[:, 0] - tex[:, -1]).max() <= inner * 1.01


def test_light_march_channels_are_the_noise_shifted_toward_the_sun(rng):
    k = reference.octave_key(3, 0)
    shift = reference.light_shift((0.6, 0.5, -0.8), 0.02)
    assert np.allclose(shift, 0.02 * np.array([0.6, -0.8]))
    tex = reference.octave_texture(16, 4, k, shift)
    uv = np.stack(np.meshgrid(np.arange(16) / 16, np.arange(16) / 16, indexing="ij"), -1)
    for c in range(4):
        assert np.allclose(tex[..., c], reference.tile_noise(uv + c * shift, 4, k))
    assert np.allclose(reference.light_shift((0, 1, 0), 0.02), 0)      # sun overhead: no shift


# -- remap and shading --------------------------------------------------------------------------------
def gpu_shade(gpu, fbm, fade, params, light):
    ctx = gpu.ctx
    prog = gpu.program(compute_shader="sky_layer/shade_points.comp")
    n = len(fbm)
    data = np.zeros((n, 8), np.float32)
    data[:, :4], data[:, 4] = fbm, fade
    src = ctx.buffer(data.tobytes())
    dst = ctx.buffer(np.full((n, 4), np.nan, np.float32).tobytes())
    try:
        bind_buffers(prog, Inputs=src, Outputs=dst)
        prog["count"].value = n
        for name in ("emptiness", "sharpness", "thickness", "color", "lit_color"):
            prog[name].value = getattr(params, name)
        prog["light"].value = tuple(light)
        prog.run(-(-n // 64))
        ctx.memory_barrier()
        return np.frombuffer(dst.read(), np.float32).reshape(n, 4).astype(np.float64)
    finally:
        src.release(), dst.release()


@pytest.mark.parametrize("look", [
    dict(), dict(emptiness=0.0, sharpness=1.0), dict(emptiness=0.5, sharpness=0.501), dict(thickness=0.0),
    dict(thickness=1e6), dict(emptiness=0.999, sharpness=1.0), dict(color=(0, 0, 0), lit_color=(5, 5, 5))])
def test_gpu_shading_matches_float64_reference(gpu, ctx, rng, look):
    params = SkyLayerSettings(**look)
    n = 2048
    fbm = rng.uniform(-0.2, 1.2, (n, 4))
    fbm[:8] = [[0, 0, 0, 0], [1, 1, 1, 1], [params.emptiness] * 4, [params.sharpness] * 4,
               [1e30, -1e30, 0, 1], [0.5, 0.9, 0.1, 0.7], [-5, -5, -5, -5], [5, 5, 5, 5]]
    fbm = fbm.astype(np.float32).astype(np.float64)
    fade = rng.uniform(0, 1, n)
    fade[:4] = [0, 1, 0, 1]
    light = rng.uniform(0, 2, 3)
    got = gpu_shade(gpu, fbm, fade, params, light)
    want = reference.shade(fbm, params, light, fade)
    assert np.isfinite(got).all() and (got[:, 3] >= 0).all() and (got[:, 3] <= 1).all()
    # a remap with a 1e-3 gap amplifies float32 input rounding by 1/gap
    gap = params.sharpness - params.emptiness
    assert np.allclose(got, want, atol=1e-5 / gap + 1e-6, rtol=1e-5), np.abs(got - want).max()


def test_remap_reference():
    f = np.array([-1.0, 0.2, 0.35, 0.5, 0.65, 2.0])
    assert np.allclose(reference.remap(f, 0.35, 0.65), [0, 0, 0, 0.5, 1, 1])
    assert np.allclose(reference.fbm(np.ones((4, 3))), 0.9375)


# -- the pass in a scene --------------------------------------------------------------------------------
SUN = Sun.from_angles(35.0, 200.0)


def render(gpu, *plugins, frames=1, pitch=0.25, yaw=0.3):
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), GroundPlugin(), *plugins)
    app.insert_resource(SUN)
    cam = app.resource(Camera)
    cam.position = np.array([123.0, 3.0, -77.0])
    cam.yaw, cam.pitch = yaw, pitch
    capture = app.graph.add_pass(CapturePass())
    app.run_frames(frames)
    return app, capture, cam


def bilinear(tex, uv):
    """GL_LINEAR + GL_REPEAT sampling of tex [x, y, c] at uv (n, 2)."""
    n = tex.shape[0]
    x = uv * n - 0.5
    i0 = np.floor(x).astype(int)
    f = x - i0
    out = 0.0
    for dx in (0, 1):
        for dy in (0, 1):
            w = (f[:, 0] if dx else 1 - f[:, 0]) * (f[:, 1] if dy else 1 - f[:, 1])
            out = out + w[:, None] * tex[(i0[:, 0] + dx) % n, (i0[:, 1] + dy) % n]
    return out


def test_pass_draws_the_reference_layer_on_the_sky_only(fresh_gpu, tmp_path):
    params = SkyLayerSettings(size=32, base_frequency=12, tile_size=40000.0, altitude=1200.0,
                            wind=((0.11, 0.0), (0.0, 0.37), (0.0, -0.2), (-0.9, 0.0)))
    plugin = SkyLayerPlugin(params, animate=False)
    app0, bg, cam = render(fresh_gpu)
    app0.close()
    app, got, _ = render(fresh_gpu, plugin)
    textures = [plugin.octaves.download(k) for k in range(4)]
    app.close()
    save_png(tmp_path, "sky_layer_pass.png", got.color)
    ground = bg.depth < 1
    assert ground.sum() > 50 and (~ground).sum() > 200
    assert np.array_equal(got.color[ground], bg.color[ground]), "the layer leaves drawn geometry alone"
    h, w = bg.depth.shape
    ys, xs = np.nonzero(~ground)
    inv = np.linalg.inv(cam.view_projection(w / h))
    ndc = np.stack([(xs + 0.5) / w * 2 - 1, (ys + 0.5) / h * 2 - 1, np.ones(len(xs)), np.ones(len(xs))], 1)
    far = (inv @ ndc.T).T
    dirs = far[:, :3] / far[:, 3:] - cam.position
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    t = (params.altitude - cam.position[1]) / dirs[:, 1]
    base = np.mod(cam.position[[0, 2]], params.tile_size)
    uv = (base + dirs[:, [0, 2]] * t[:, None]) / params.tile_size
    offsets = scroll_offsets(params.wind, 0.0)
    fbm = reference.fbm(np.stack([bilinear(textures[k], uv + offsets[k]) for k in range(4)]))
    fade = np.clip(dirs[:, 1] / params.horizon_fade, 0, 1)
    fade = fade * fade * (3 - 2 * fade)
    layer = reference.shade(fbm, params, layer_light(SUN)[1], fade)
    want = layer[:, :3] + (1.0 - layer[:, 3:]) * bg.color[ys, xs, :3]
    # compare where a pixel covers less than a texel (mip level 0, plain bilinear); nearer the horizon
    # the GPU filters from coarser mip levels, which the reference does not model
    steep = dirs[:, 1] > 0.25
    assert steep.sum() > 200 and (layer[steep, 3] > 0.3).sum() > 20 and (layer[steep, 3] < 0.05).sum() > 20, \
        "clouds and clear sky both tested"
    err = np.abs(got.color[ys, xs, :3] - want)
    assert (err[steep] <= 4e-3 + 1e-2 * want[steep]).all(), err[steep].max()
    assert np.median(err) < 1e-3
    # color.a, the sky occlusion: 0 on the open sky before, the layer's coverage after; 1 on the ground
    assert np.all(bg.color[ys, xs, 3] == 0.0) and np.all(bg.color[ground][:, 3] == 1.0)
    a_err = np.abs(got.color[ys, xs, 3] - layer[:, 3])
    assert (a_err[steep] <= 4e-3 + 1e-2 * layer[steep, 3]).all(), a_err[steep].max()


def save_png(folder, name, hdr):
    from PIL import Image
    img = np.clip(hdr[::-1, :, :3] / (1 + hdr[::-1, :, :3]), 0, 1) ** (1 / 2.2)
    Image.fromarray((img * 255).astype(np.uint8)).save(folder / name)


def test_layer_scrolls_with_time_and_rebakes_only_when_the_sun_turns(fresh_gpu):
    plugin = SkyLayerPlugin(size=32, rebake_tolerance=0.05)
    app, cap, _ = render(fresh_gpu, plugin, pitch=0.6)
    first = cap.color.copy()
    app.run_frames(30, dt=1 / 10)
    assert np.abs(cap.color - first).mean() > 1e-3, "the clouds drift"
    assert plugin.octaves.bakes == 1
    sun = app.resource(Sun)
    sun.direction = np.array(Sun.from_angles(35.0, 200.5).direction)      # turned by 0.5°: keep
    app.run_frames(1)
    assert plugin.octaves.bakes == 1
    sun.direction = np.array(Sun.from_angles(35.0, 230.0).direction)      # turned by 30°: re-bake
    app.run_frames(1)
    assert plugin.octaves.bakes == 2
    plugin.configure(seed=5)
    app.run_frames(1)
    assert plugin.octaves.bakes == 3
    app.close()


def test_octaves_scroll_at_different_speeds_and_directions():
    wind = np.asarray(SkyLayerSettings().wind)
    speeds = np.linalg.norm(wind, axis=1)
    assert np.allclose(speeds / speeds[0], [1, 1.5, 2, 2.5])
    assert len({tuple(np.sign(w)) for w in wind}) == 4
    assert np.allclose(scroll_offsets(wind, 1000.0), np.mod(wind * 1000.0, 1.0))
    assert (scroll_offsets(wind, 1e9) >= 0).all() and (scroll_offsets(wind, 1e9) < 1).all()


def test_camera_above_the_layer_and_looking_down_draws_nothing(fresh_gpu):
    app0, bg, _ = render(fresh_gpu, pitch=0.3)
    app0.close()
    app, got, _ = render(fresh_gpu, SkyLayerPlugin(size=16, altitude=-10.0), pitch=0.3)
    app.close()
    assert np.array_equal(got.color, bg.color)


@pytest.mark.parametrize("change, message", [
    (dict(emptiness=-0.1), "SkyLayerSettings.emptiness must be a finite number >= 0.0 and <= 1.0"),
    (dict(sharpness=1.5), "sharpness"), (dict(emptiness=0.6, sharpness=0.6), "sharpness must exceed emptiness"),
    (dict(thickness=-1), "thickness"), (dict(color=(1, 1)), "SkyLayerSettings.color must be 3 non-negative"),
    (dict(tile_size=0), "tile_size must be a finite number > 0"), (dict(size=8), "size must be a whole number 16..2048"),
    (dict(wind=((1, 0),) * 3), "wind must be 4"), (dict(wind=((1, 0), (0, 1), (0, math.nan), (1, 1))), r"wind\[2\]"),
    (dict(base_frequency=0), "1..64"), (dict(light_step=0.5), "light_step"), (dict(horizon_fade=0), "horizon_fade"),
    (dict(altitude=math.inf), "altitude"), (dict(cover=0.5), "unknown SkyLayerSettings setting"),
])
def test_bad_settings_are_refused_and_nothing_is_applied(change, message):
    plugin = SkyLayerPlugin()
    before = plugin.settings
    with pytest.raises(ValueError, match=message):
        plugin.configure(**{"thickness": 2.0, **change})
    assert plugin.settings is before
    with pytest.raises(ValueError):
        SkyLayerPlugin(**change)


def test_scene_without_the_layer_compiles_and_runs_none_of_it(fresh_gpu):
    app = App(fresh_gpu).add_plugins(DefaultPlugins(overlay=False), GroundPlugin())
    app.run_frames(2)
    assert "sky_layer" not in app.graph.dump()
    assert not any(f.startswith("sky_layer/") for f in fresh_gpu.compiled_files)
    app.close()


def test_sky_layer_demo_runs_headless(tmp_path):
    from PIL import Image
    from atmos.cli import main
    out = tmp_path / "sky"
    assert main(["demo", "sky_layer", "--headless", "--frames", "3", "--size", "64x36",
                 "--out", str(out), "--quiet"]) == 0
    img = np.asarray(Image.open(out / "frame_00002.png"), float)
    assert img.std() > 5, "not a blank frame"
