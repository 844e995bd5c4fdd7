"""Light shafts (thesis 7.3.2): radial blur and whole pass against the float64 references, extremes, a look."""
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.lighting import Sun
from atmos.graph import PassBuilder, RenderPass
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.light_shafts import LightShaftSettings, LightShaftsPlugin, blur_uniforms, reference, screen_sun
from atmos.plugins.light_shafts.plugin import MASK
from atmos.plugins.sky import SkyPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.terrain import TerrainPlugin
from atmos.plugins.template_volume import TemplateVolumePlugin, VolumeBox
from atmos.render_core import COLOR, DEPTH, CapturePass
from test_cloud_shadows import FillPass, pass_plugin, save_png
from fullscreen_probe import run_fullscreen


def random_params(rng, **fixed) -> LightShaftSettings:
    values = dict(samples=int(rng.integers(1, 65)), density=rng.uniform(0.2, 1.0), decay=rng.uniform(0.8, 1.0),
                  weight=rng.uniform(0.01, 0.2), exposure=rng.uniform(0.2, 2.0), threshold=rng.uniform(0.0, 1.0), ceiling=rng.uniform(0.1, 3.0),
                  radius=rng.uniform(0.1, 1.0))
    values.update(fixed)
    return LightShaftSettings(mode="screen", **values)


def gpu_blur(gpu, mask: np.ndarray, sun_uv, params, strength=1.0) -> np.ndarray:
    """The blur shader alone on an (h, w, 3) mask (float16 RGBA texture, linear filtering)."""
    h, w = mask.shape[:2]
    rgba = np.concatenate([mask, np.zeros((h, w, 1))], -1).astype(np.float16)
    return run_fullscreen(gpu, "light_shafts/blur.frag", (w, h), {"mask": rgba},
                          lambda program: blur_uniforms(program, sun_uv, params, strength))


@pytest.mark.parametrize("where", ["random", "centre", "pixel_centre", "edge", "outside", "far_outside"])
def test_blur_matches_reference_on_small_random_masks(gpu, ctx, rng, where):
    w, h = (int(n) for n in rng.integers(3, 24, 2))
    mask = rng.uniform(0, 4, (h, w, 3)).astype(np.float16).astype(np.float64)
    sun_uv = {"random": rng.uniform(-0.5, 1.5, 2), "centre": (0.5, 0.5), "pixel_centre": (0.5 / w, 1.5 / h),
              "edge": (1.0, rng.uniform(0, 1)), "outside": (rng.uniform(1.2, 2), rng.uniform(-1, -0.2)),
              "far_outside": (64.0, -64.0)}[where]
    # outside: at most 2/64 of the screen per tap, less than a texel of the largest mask, so the corner
    # nearest the sun keeps its first tap on the mask and the comparison is not of two black images
    params = random_params(rng, **({"samples": 64} if where == "outside" else {}))
    strength = rng.uniform(0.1, 1.0)
    out = gpu_blur(gpu, mask, sun_uv, params, strength)
    assert np.isfinite(out).all(), "every texel written, none NaN"
    expected = reference.radial_blur(mask, sun_uv, params, strength)
    assert np.allclose(out[..., :3], expected, rtol=1e-4, atol=1e-5 * expected.max())
    assert np.all(out[..., 3] == 0.0)
    assert expected.max() > 0 or where == "far_outside"     # all taps may leave the mask there


def test_the_blur_adds_at_most_hdr_max_whatever_its_settings(gpu, ctx):
    """weight and exposure have no upper bound: their product, up to 1e600, is held at float32's largest
    and the sum at HDR_MAX, so blending it onto the float16 colour stays finite (on a float32 target the
    uncapped sum would be 1e30 or inf here)."""
    from atmos.render_core import HDR_MAX
    mask = np.full((8, 8, 3), 65504.0)
    for extreme in (dict(weight=1e30), dict(exposure=1e30), dict(weight=1e300, exposure=1e300)):
        params = LightShaftSettings(mode="screen", **extreme)
        out = gpu_blur(gpu, mask, (0.5, 0.5), params)
        assert np.isfinite(out).all() and out[..., :3].max() == HDR_MAX, (extreme, out.max())
        assert np.allclose(out[..., :3], reference.radial_blur(mask, (0.5, 0.5), params))


def test_blur_reference_by_hand():
    """One bright texel: the shaft runs from it away from the sun, falling off by decay per tap."""
    mask = np.zeros((1, 9, 1))
    mask[0, 2] = 1.0                                    # x centre uv = 2.5 / 9
    p = LightShaftSettings(samples=4, density=1.0, decay=0.5, weight=1.0, exposure=1.0)
    out = reference.radial_blur(mask, (0.5 / 9, 0.5), p)[0, :, 0]   # sun at pixel 0's centre
    # pixel x takes taps at x - i·x/4 (i = 1..4), tap i weighing 0.5^(i-1): pixel 4 hits 2 with tap 2,
    # pixel 8 with tap 3, pixel 6 half-hits it (at 1.5) with tap 3, pixel 2 itself with tap 1 (at 1.5)
    assert out[4] == pytest.approx(0.5) and out[8] == pytest.approx(0.25) and out[6] == pytest.approx(0.125)
    assert out[2] == pytest.approx(0.5)
    assert out[0] == 0.0 and out[1] == 0.0              # nothing between the bright texel and the sun


def sun_toward(cam: Camera, size, uv) -> np.ndarray:
    """The direction toward a sun seen at screen ``uv``."""
    x, y = uv
    ndc = np.array([2 * x - 1, 2 * y - 1, 1.0, 1.0])
    far = np.linalg.inv(cam.view_projection(size[0] / size[1])) @ ndc
    d = far[:3] / far[3] - cam.position
    return d / np.linalg.norm(d)


def shafts_app(gpu, params, scene=False, extra=()):
    fill, probe = FillPass(), CapturePass()
    drawn = [SkyGradientPlugin(), GroundPlugin(), *extra] if scene else [pass_plugin(fill)]
    plugin = LightShaftsPlugin(params)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), *drawn, plugin, pass_plugin(probe))
    app.startup()
    return app, plugin, fill, probe


def test_pass_matches_reference_on_random_frames(gpu, ctx, rng):
    size = gpu.size
    w, h = size
    params = random_params(rng, downsample=1)
    app, _, fill, probe = shafts_app(gpu, params)
    cam = app.resource(Camera)
    cam.position = rng.uniform(-50, 50, 3)
    cam.yaw, cam.pitch = rng.uniform(-math.pi, math.pi), rng.uniform(0.6, 0.9)   # sun well above the horizon
    sun_uv = rng.uniform(0.1, 0.9, 2)
    app.insert_resource(Sun(sun_toward(cam, size, sun_uv)))
    color = rng.uniform(0.0, 3.0, (h, w, 4))
    pick = rng.random((h, w))           # alpha (sky occlusion): open sky, opaque, partial, out of range
    color[..., 3] = np.where(pick < 0.3, 0.0, np.where(pick < 0.45, 1.0, rng.uniform(-0.3, 1.3, (h, w))))
    depth = np.where(rng.random((h, w)) < 0.5, 1.0, rng.uniform(0.5, 0.99, (h, w)))
    fill.color, fill.depth = color, depth
    app.render()
    assert ctx.error == "GL_NO_ERROR"
    where = screen_sun(cam, w / h, app.resource(Sun).direction, params)
    assert np.allclose(where.uv, sun_uv, atol=1e-9) and where.strength > 0
    before = color.astype(np.float16).astype(np.float64)
    mask = reference.occlusion_mask(before, probe.depth, where.uv, params)
    shafts = reference.radial_blur(mask, where.uv, params, where.strength)
    assert np.isfinite(probe.color).all()
    # three f2 round trips (mask, blur, sum) bound the error
    assert np.allclose(probe.color[..., :3], before[..., :3] + shafts, rtol=3e-3, atol=1e-3)
    assert np.array_equal(probe.color[..., 3], before[..., 3])
    assert shafts.max() > 0.01, "the random frame has shafts to compare"
    app.close()


class BrightLayerPass(RenderPass):
    """Premultiplied (rgb·a, a) over screen rectangles, blended like the cloud sprites (ONE,
    ONE_MINUS_SRC_ALPHA on colour and alpha), no depth: a sunlit cloud drawn over the sky."""
    name = "test_bright_layer"
    phase = "translucent"

    def __init__(self, rects):
        self.rects = rects              # [((x, y, w, h) in pixels, rgb, alpha)]
        self.program = None

    def setup(self, builder: PassBuilder) -> None:
        builder.read(COLOR)
        builder.write(COLOR)

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="test/solid.frag")

    def execute(self, frame) -> None:
        ctx = frame.gpu.ctx
        frame.framebuffer(color=[COLOR]).use()
        ctx.enable(ctx.BLEND)
        ctx.blend_func = ctx.ONE, ctx.ONE_MINUS_SRC_ALPHA
        try:
            for rect, rgb, alpha in self.rects:
                ctx.scissor = rect
                self.program["color"].value = (*(np.asarray(rgb, float) * alpha), alpha)
                frame.fullscreen(self.program)
        finally:
            ctx.scissor = None


class CaptureBefore(CapturePass):
    """The capture of "color" as the media phase left it (a versioned read): it runs in phase post
    before the shafts write the next version."""
    name = "capture_before_shafts"
    phase = "post"

    def setup(self, builder: PassBuilder) -> None:
        builder.read(COLOR, at="media")
        builder.read(DEPTH)
        builder.side_effect()


class MaskProbe(RenderPass):
    """Copies the light shafts' occlusion mask (h, w, 4) to numpy."""
    name = "test_mask_probe"
    phase = "post"

    def __init__(self):
        self.mask = None

    def setup(self, builder: PassBuilder) -> None:
        builder.read(MASK)
        builder.side_effect()

    def execute(self, frame) -> None:
        tex = frame.resource(MASK)
        w, h = tex.size
        self.mask = np.frombuffer(tex.read(), np.float16).reshape(h, w, 4).astype(np.float64)


def test_bright_cloud_over_the_sky_cuts_the_mask_through_alpha(gpu, ctx):
    """A layer brighter than the sun's glow, drawn over the sky next to the sun: the old rule (bright
    sky pixels are sky) kept it in the mask; with color.a (sky occlusion) it is cut, partly where
    it is partly transparent, and the open sky around it still casts."""
    w, h = gpu.size
    params = LightShaftSettings(mode="screen", downsample=1, threshold=0.6, ceiling=3.0, radius=0.6)
    opaque = ((int(0.55 * w), int(0.45 * h), int(0.15 * w), int(0.25 * h)), (6.0, 5.5, 5.0), 1.0)
    half = ((int(0.25 * w), int(0.45 * h), int(0.15 * w), int(0.25 * h)), (6.0, 5.5, 5.0), 0.5)
    before, probe = CaptureBefore(), MaskProbe()
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(),
                               pass_plugin(BrightLayerPass([opaque, half])), pass_plugin(before),
                               LightShaftsPlugin(params), pass_plugin(probe))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 2.0, 0.0])
    cam.yaw, cam.pitch = 0.3, 0.25
    sun_uv = (0.5, 0.55)
    app.insert_resource(Sun(sun_toward(cam, gpu.size, sun_uv)))
    app.render()
    assert ctx.error == "GL_NO_ERROR"
    color, depth = before.color, before.depth
    where = screen_sun(cam, w / h, app.resource(Sun).direction, params)
    assert np.allclose(where.uv, sun_uv, atol=1e-9)

    def inside(rect):
        (x, y, rw, rh), _, _ = rect
        return (slice(y + 1, y + rh - 1), slice(x + 1, x + rw - 1))

    # the convention after the sky and ground passes and the layer: sky 0, ground 1, layer its coverage
    sky = depth >= 1.0
    layer = np.zeros((h, w), bool)
    for rect in (opaque, half):
        (x, y, rw, rh), _, _ = rect
        layer[y:y + rh, x:x + rw] = True
    assert sky.mean() > 0.3 and (~sky).mean() > 0.1
    assert np.all(color[sky & ~layer, 3] == 0.0) and np.all(color[~sky & ~layer, 3] == 1.0)
    assert np.all(color[inside(opaque)][..., 3] == 1.0)
    assert np.allclose(color[inside(half)][..., 3][sky[inside(half)]], 0.5, atol=1e-3)

    want = reference.occlusion_mask(color, depth, where.uv, params)
    luminance_only = reference.occlusion_mask(np.concatenate([color[..., :3], np.zeros((h, w, 1))], -1), depth,
                                              where.uv, params)
    got = probe.mask[..., :3]
    assert np.isfinite(got).all() and np.all(probe.mask[..., 3] == 0.0)
    assert np.allclose(got, want, rtol=3e-3, atol=1e-3), np.abs(got - want).max()
    assert luminance_only[inside(opaque)].min() > 0.2, "the old rule would have kept the bright layer as sky"
    assert got[inside(opaque)].max() == 0.0, "the opaque layer is cut from the mask"
    kept = luminance_only[inside(half)].sum(-1)
    assert np.allclose(got[inside(half)].sum(-1), 0.5 * kept, rtol=5e-3, atol=1e-3)
    open_near_sun = sky & ~layer & (reference.pixel_uv(w, h)[..., 0] < 0.55) & (reference.pixel_uv(w, h)[..., 1] > 0.7)
    assert got[open_near_sun].max() > 0.05, "the open sky next to the layer still casts shafts"
    app.close()


@pytest.mark.parametrize("scene", ["clear", "sky_gradient+ground", "sky+terrain"])
def test_colour_alpha_is_the_sky_occlusion_and_the_screen_alpha_is_one(gpu, ctx, scene):
    """color.a (atmos.render_core): 0 on the open sky (or nothing drawn), 1 on opaque geometry; the
    screen gets alpha 1 from present."""
    drawn = {"clear": [], "sky_gradient+ground": [SkyGradientPlugin(), GroundPlugin()],
             "sky+terrain": [SkyPlugin(), TerrainPlugin()]}[scene]
    probe = CapturePass()
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), *drawn, pass_plugin(probe))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 30.0, 0.0])
    cam.yaw, cam.pitch = 0.4, -0.05
    app.insert_resource(Sun(np.array([0.3, 0.4, -1.0])))
    app.render()
    sky = probe.depth >= 1.0
    assert np.all(probe.color[sky, 3] == 0.0) and np.all(probe.color[~sky, 3] == 1.0)
    if scene != "clear":
        assert 0.1 < sky.mean() < 0.9
    w, h = gpu.size
    screen = np.frombuffer(gpu.target.read(viewport=(0, 0, w, h), components=4, alignment=1), np.uint8)
    assert np.all(screen.reshape(h, w, 4)[..., 3] == 255)
    app.close()


def test_screen_sun_fades():
    cam = Camera(position=np.array([0.0, 0.0, 0.0]))
    cam.look_at((0.0, 0.3, -1.0))
    p = LightShaftSettings()
    ahead = screen_sun(cam, 16 / 9, cam.forward(), p)
    assert ahead.uv == pytest.approx((0.5, 0.5)) and ahead.strength == pytest.approx(1.0)
    assert screen_sun(cam, 16 / 9, -cam.forward(), p).strength == 0.0               # behind the camera
    assert screen_sun(cam, 16 / 9, (0.0, -0.2, -1.0), p).strength == 0.0             # below the horizon
    assert screen_sun(cam, 16 / 9, (1.0, 0.3, 0.0), p).strength == 0.0               # 90° off: far outside
    assert screen_sun(cam, 16 / 9, (0, 0, 0), p).strength == 0.0                      # no direction
    side = screen_sun(cam, 1.0, sun_toward(cam, (1, 1), (1.0, 0.5)), p)             # on the screen edge
    assert side.uv[0] == pytest.approx(1.0) and side.strength == pytest.approx(1.0, abs=0.05)
    grazing = screen_sun(cam, 1.0, sun_toward(cam, (1, 1), (1.0 + p.edge_fade / 2, 0.5)), p)
    assert 0.0 < grazing.strength < side.strength                                   # fading out past it
    almost_behind = screen_sun(cam, 1.0, (1.0, 0.3, -0.01), p)
    assert all(np.isfinite(almost_behind.uv)) and almost_behind.strength == 0.0
    for bad in (dict(samples=0), dict(samples=1000), dict(decay=1.5), dict(downsample=0), dict(radius=0.0),
                dict(exposure=-1.0), dict(density=math.inf), dict(froxels=(0, 4, 4)), dict(froxels=(8, 8)),
                dict(froxels=(8, 8, 300)), dict(froxels="160x90x64")):
        with pytest.raises(ValueError, match=next(iter(bad))):
            LightShaftSettings(**bad)
    with pytest.raises(ValueError, match=r"LightShaftSettings.froxels must be None or three ints in \[1, 256\]"):
        LightShaftSettings(froxels=(1.5, 2, 2))
    assert LightShaftSettings(froxels=[8, 4, 2]).froxels == (8, 4, 2) and LightShaftSettings(froxels=None).froxels is None


@pytest.mark.parametrize("case", ["behind", "below", "edge", "centre", "far_outside", "tiny", "minimized"])
def test_extremes_no_nan_no_gl_error(case):
    size = {"tiny": (1, 1), "minimized": (0, 0)}.get(case, (96, 54))
    gpu = create_headless(size)
    app, plugin, _, probe = shafts_app(gpu, LightShaftSettings(mode="screen"), scene=True)
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 5.0, 0.0])
    cam.look_at((0.0, 8.0, -20.0))
    uv = {"edge": (1.0, 0.6), "centre": (0.5, 0.5), "far_outside": (9.0, 0.5)}.get(case, (0.5, 0.7))
    sun = sun_toward(cam, gpu.size, uv)
    if case == "behind":
        sun = -cam.forward() + np.array([0.0, 0.5, 0.0])
    elif case == "below":
        sun = np.array([0.0, -0.1, -1.0])
    app.insert_resource(Sun(sun))
    plugin.configure(exposure=0.0)
    app.render()
    base = probe.color.copy()
    plugin.configure(exposure=0.5)
    app.render()
    assert gpu.ctx.error == "GL_NO_ERROR"
    assert np.isfinite(probe.color).all() and np.isfinite(gpu.read_pixels()).all()
    added = probe.color - base
    assert added.min() >= 0.0
    if case in ("behind", "below", "far_outside"):
        assert np.array_equal(probe.color, base)
    elif case in ("edge", "centre"):
        assert added[..., :3].max() > 0.05
    app.close()
    gpu.release()


def test_shafts_around_clouds_at_sunset_look_right():
    """A low orange sun just above drifting cloud blobs: a glow streaked by the clouds' shadows."""
    gpu = create_headless((480, 270))
    box = VolumeBox(center=(0.0, 16.0, -40.0), size=(70.0, 14.0, 30.0))
    params = LightShaftSettings(mode="screen", exposure=1.0, threshold=0.3)
    probe = CapturePass()
    plugin = LightShaftsPlugin(params)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False),
                               SkyGradientPlugin(zenith=(0.06, 0.1, 0.25), horizon=(0.55, 0.4, 0.3)), GroundPlugin(),
                               TemplateVolumePlugin(resolution=(32, 16, 32), slices=4, box=box), plugin, pass_plugin(probe))
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 3.0, 20.0])
    cam.look_at((0.0, 14.0, -40.0))
    app.insert_resource(Sun(sun_toward(cam, gpu.size, (0.42, 0.52)), color=(1.0, 0.6, 0.3)))
    shots = []
    for n in range(2):
        app.run_frames(12, 1 / 30)
        shots.append(gpu.read_pixels())
        save_png(f"light_shafts_{n + 1}.png", shots[-1])
    with_shafts = probe.color.copy()
    plugin.configure(exposure=0.0)
    app.render()
    save_png("light_shafts_without.png", gpu.read_pixels())
    added = (with_shafts - probe.color)[..., :3].max(-1)
    assert gpu.ctx.error == "GL_NO_ERROR" and np.isfinite(with_shafts).all()
    assert 0.02 < (added > 0.05).mean() < 0.9, "shafts cover part of the frame"
    assert added.min() >= 0.0
    assert np.abs(shots[0].astype(float) - shots[1].astype(float)).mean() > 0.5, "they change as the clouds move"
    app.close()
    gpu.release()
