"""The Preetham sky: GPU against the float64 reference on random directions and suns, every pixel
written, extremes finite, colours through a day, stars only at night, checked settings, the demo."""
import math
import os

import numpy as np
import pytest
from PIL import Image

from atmos.app import App
from atmos.camera import Camera, view_basis
from atmos.frame_constants import bind_frame
from atmos.cli import main
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.lighting import Sun
from atmos.plugins.daylight import solar_direction
from atmos.plugins.ground import GroundPlugin
from atmos.lighting import sky_light
from atmos.plugins.sky import SkySettings, SkyPlugin, evaluate_sky, sky_color, sky_radiance
from atmos.plugins.sky.preetham import preetham_rgb
from atmos.plugins.sky.shader import set_sky_uniforms, sky_defines
from atmos.sun_disc import LIMB_FLOOR
from fullscreen_probe import run_fullscreen

OUT = os.path.join(os.path.dirname(__file__), "..", "out", "sky")


def save_png(name: str, rgb_uint8: np.ndarray) -> str:
    os.makedirs(OUT, exist_ok=True)
    path = os.path.abspath(os.path.join(OUT, name))
    Image.fromarray(rgb_uint8).save(path)
    return path


def unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_dirs(rng, n):
    return unit(rng.normal(size=(n, 3))).astype(np.float32)


def random_sun(rng, elevation_range=(-40.0, 90.0)):
    """A unit sun direction in float32 values, so the GPU's uniform and the reference's input agree."""
    return Sun.from_angles(rng.uniform(*elevation_range), rng.uniform(0.0, 360.0)).direction.astype(np.float32)


def near(gpu_rgb, ref_rgb, rtol=2e-3, atol=2e-4):
    """Largest excess of |gpu − ref| over rtol·|ref| + atol (≤ 0 passes)."""
    return float(np.max(np.abs(gpu_rgb - ref_rgb) - (rtol * np.abs(ref_rgb) + atol)))


def random_params(rng, **fixed):
    settings = dict(turbidity=rng.uniform(2.0, 10.0), scale=rng.uniform(0.01, 0.1),
                    sun_size_deg=rng.uniform(0.3, 3.0), sun_gain=rng.uniform(1.0, 30.0),
                    night=tuple(rng.uniform(0.0, 0.05, 3)), stars=True, star_density=rng.uniform(0.05, 0.6),
                    star_brightness=rng.uniform(0.5, 8.0), twinkle=rng.uniform(0.0, 1.0))
    settings.update(fixed)
    return SkySettings(**settings)


# -- GPU against the float64 reference ------------------------------------------------------------

def test_gpu_sky_matches_reference_on_random_directions_and_suns(gpu, ctx, rng):
    for _ in range(6):
        params = random_params(rng)
        sun = random_sun(rng)
        color = rng.uniform(0.0, 1.2, 3)
        # random directions, and directions within a few sun radii (the disc and its edge)
        around = unit(sun + rng.normal(size=(2000, 3)) * math.radians(params.sun_size_deg))
        dirs = np.concatenate([random_dirs(rng, 6000), around.astype(np.float32)])
        time, pixel_angle = rng.uniform(0.0, 500.0), rng.uniform(0.0, 0.02)
        got = evaluate_sky(gpu, dirs, sun, color, params, time, pixel_angle)
        want = sky_color(dirs, sun, color, params, time, pixel_angle)
        assert np.isfinite(got).all(), "an output was not written (NaN prefill) or is NaN"
        assert near(got, want) <= 0, (params, sun)
        assert (want >= 0).all()


def test_stars_on_the_gpu_are_the_reference_stars(gpu, ctx, rng):
    params = random_params(rng, star_density=0.5, twinkle=0.5)
    sun = Sun.from_angles(-30.0, 0.0).direction
    dirs = random_dirs(rng, 20000)
    dirs = dirs[dirs[:, 1] > 0.2]
    dark = SkySettings(stars=False, night=params.night, turbidity=params.turbidity)
    time = rng.uniform(0.0, 100.0)
    got = evaluate_sky(gpu, dirs, sun, (0, 0, 0), params, time) - evaluate_sky(gpu, dirs, sun, (0, 0, 0), dark)
    want = sky_color(dirs, sun, (0, 0, 0), params, time) - sky_color(dirs, sun, (0, 0, 0), dark)
    lit = want.max(axis=1) > 1e-3
    assert 0.01 < lit.mean() < 0.5, "some random directions see a star, most do not"
    assert near(got, want, 5e-3, 1e-4) <= 0


def render_sky(gpu, camera: Camera, size, params: SkySettings, sun, sun_color, time=0.0):
    """(h, w, 4) sky.frag output (row 0 at the bottom)."""
    w, h = size

    def uniforms(prog):
        bind_frame(gpu, camera, size=(w, h))          # view_basis: the frame block, outside a graph
        set_sky_uniforms(prog, params, sun, sun_color, time, camera.fov_y / h)
    return run_fullscreen(gpu, "sky/sky.frag", size, None, uniforms, defines=sky_defines())


def pixel_centres(size):
    w, h = size
    u, v = np.meshgrid((np.arange(w) + 0.5) / w, (np.arange(h) + 0.5) / h)
    return u * 2 - 1, v * 2 - 1


def pixel_dirs(camera: Camera, size) -> np.ndarray:
    """(h, w, 3) the view ray through each pixel centre (row 0 at the bottom), float64."""
    x, y = pixel_centres(size)
    return unit(np.stack([x, y, np.ones_like(x)], axis=-1) @ view_basis(camera, size[0] / size[1]).T)


def test_view_basis_rays_are_the_unprojected_rays(rng):
    for _ in range(10):
        cam = Camera(position=rng.uniform(-100, 100, 3), yaw=rng.uniform(-4, 4), pitch=rng.uniform(-1.5, 1.5),
                     fov_y=rng.uniform(0.2, 2.5), near=rng.uniform(0.01, 1), far=rng.uniform(10, 5000))
        size = tuple(rng.integers(1, 300, 2))
        x, y = pixel_centres(size)
        p = np.stack([x, y, np.ones_like(x), np.ones_like(x)], axis=-1) @ np.linalg.inv(
            cam.view_projection(size[0] / size[1])).T
        assert np.allclose(pixel_dirs(cam, size), unit(p[..., :3] / p[..., 3:] - cam.position), atol=1e-9)


def test_rendered_sky_matches_reference_in_every_pixel(gpu, ctx, rng):
    size = (48, 32)
    for k in range(4):
        cam = Camera(position=rng.uniform(-50, 50, 3), yaw=rng.uniform(-math.pi, math.pi),
                     pitch=rng.uniform(-1.5, 1.5), fov_y=math.radians(rng.uniform(30, 100)))
        params = random_params(rng, stars=False)
        sun = unit(cam.forward() + rng.normal(size=3) * 0.3)      # the sun in or near the view
        img = render_sky(gpu, cam, size, params, sun, (1.0, 0.9, 0.8))
        assert np.isfinite(img).all(), "a pixel was not written"
        assert np.all(img[..., 3] == 0.0)                  # open sky: nothing occludes it (render_core)
        want = sky_color(pixel_dirs(cam, size), sun, (1.0, 0.9, 0.8), params, pixel_angle=cam.fov_y / size[1])
        assert near(img[..., :3], want, 5e-3, 1e-3) <= 0, (cam, params, sun)
        save_png(f"render_{k}.png", (np.clip(img[::-1, :, :3] / (1 + img[::-1, :, :3]), 0, 1) ** (1 / 2.2) * 255)
                 .astype(np.uint8))


# -- extremes --------------------------------------------------------------------------------------

EXTREME_SUNS = [(0, 1, 0), (1, 0, 0), (0, 0, -1), (0.3, 1e-7, -1), (0, -1, 0), (0.2, -0.05, 1), (1, -1e-7, 0)]
EXTREME_VIEWS = [(0, 1, 0), (0, -1, 0), (1, 0, 0), (0, 0, 1), (0, 1e-7, -1), (0, -1e-7, 1), (1, 1, 1), (-1, -1, -1)]


@pytest.mark.parametrize("turbidity", [2.0, 10.0])
def test_extreme_suns_and_views_are_finite_on_gpu_and_reference(gpu, ctx, turbidity):
    views = unit(np.array(EXTREME_VIEWS + EXTREME_SUNS, np.float64))
    for s in EXTREME_SUNS:
        for stars in (False, True):
            params = SkySettings(turbidity=turbidity, stars=stars, star_density=1.0)
            want = sky_color(views, s, (1, 1, 1), params, time=1e4, pixel_angle=1.0)
            got = evaluate_sky(gpu, views, s, (1, 1, 1), params, time=1e4, pixel_angle=1.0)
            assert np.isfinite(want).all() and np.isfinite(got).all() and (got >= 0).all(), s
            assert near(got, want, 3e-3, 1e-3) <= 0, s


@pytest.mark.parametrize("pitch", [math.pi / 2, -math.pi / 2, 1.55, -1.55])
@pytest.mark.parametrize("near_far", [(1e-4, 1e7), (0.1, 0.2), (10.0, 2000.0)])
def test_camera_straight_up_or_down_and_extreme_planes_render_finite(gpu, ctx, pitch, near_far):
    cam = Camera(position=np.array([0.0, 1.0, 0.0]), yaw=0.3, pitch=pitch, near=near_far[0], far=near_far[1])
    img = render_sky(gpu, cam, (16, 16), SkySettings(), Sun.from_angles(20, 0).direction, (1, 1, 1), 3.0)
    assert np.isfinite(img).all() and (img[..., :3] >= 0).all()
    sky = img[..., :3].mean()
    assert (sky > 0.05) if pitch > 0 else (sky < 0.2), "looking up sees the sky, down the dimmed horizon"


def test_bad_inputs_raise_clear_errors_and_change_nothing():
    for kwargs, words in [({"turbidity": 1.0}, "turbidity"), ({"turbidity": 11}, "[2.0, 10.0]"),
                          ({"scale": 0}, "scale"), ({"sun_size_deg": -1}, "sun_size_deg"),
                          ({"night": (1, 2)}, "night"), ({"stars": "yes"}, "True or False"),
                          ({"star_density": 2}, "star_density"), ({"twinkle": math.nan}, "twinkle")]:
        with pytest.raises(ValueError, match=words.replace("[", r"\[").replace("]", r"\]")):
            SkySettings(**kwargs)
        with pytest.raises(ValueError):
            SkyPlugin(**kwargs)
    plugin = SkyPlugin(turbidity=3.0)
    before = plugin.settings
    with pytest.raises(ValueError, match="scale"):
        plugin.configure(turbidity=5.0, scale=-1.0)
    with pytest.raises(ValueError, match="unknown SkySettings setting"):
        plugin.configure(turbidity=5.0, nosuch=1)
    assert plugin.settings is before
    assert plugin.configure(turbidity=5.0).turbidity == 5.0
    with pytest.raises(ValueError, match="view_dir"):
        sky_radiance((0, 0, 0), (0, 1, 0))
    with pytest.raises(ValueError, match="sun_dir"):
        sky_radiance((0, 1, 0), (np.nan, 1, 0))
    with pytest.raises(ValueError, match="turbidity"):
        sky_radiance((0, 1, 0), (0, 1, 0), turbidity=12.0)


# -- behaviour ---------------------------------------------------------------------------------------

def test_preetham_reference_properties():
    # the zenith value is the model's zenith luminance; the sky is brightest around the sun
    s = Sun.from_angles(40.0, 0.0).direction
    up = preetham_rgb((0, 1, 0), s, 3.0)
    toward = preetham_rgb(unit(s + np.array([0, 0.05, 0])), s, 3.0)
    away = preetham_rgb(unit(-s * np.array([1, -1, 1])), s, 3.0)
    assert toward.sum() > up.sum() and toward.sum() > away.sum()
    assert up[2] > up[0], "a clear zenith is blue"
    assert preetham_rgb((0, 1, 0), s, 8.0).sum() > up.sum(), "haze brightens the sky"
    # the helper is continuous across the horizon for the sun and for the view
    e = 1e-9
    for a, b in [(((0, e, 1), (0, 1, 0)), ((0, -e, 1), (0, 1, 0))), (((0, 1, 0), (1, e, 0)), ((0, 1, 0), (1, -e, 0)))]:
        assert np.allclose(sky_radiance(*a), sky_radiance(*b), rtol=1e-6)


def test_sky_changes_colour_through_a_day_and_is_reddish_near_sunset(gpu, ctx):
    params = SkySettings(stars=False)
    rows = []
    for hours in np.arange(0.0, 24.0, 0.25):
        s = solar_direction(hours)
        flat = unit(np.array([s[0], 0.03, s[2]]))              # the horizon under the sun
        views = np.array([(0, 1, 0), flat], np.float32)
        got = evaluate_sky(gpu, views, s, sky_light(s)[0], params)
        rows.append((hours, s[1], got[0], got[1]))
    noon = max(rows, key=lambda r: r[1])
    midnight = min(rows, key=lambda r: r[1])
    sunset = min((r for r in rows if r[0] > 12 and r[1] > 0), key=lambda r: r[1])
    assert noon[2][2] > noon[2][0], "blue zenith at noon"
    assert sunset[3][0] > 1.5 * sunset[3][2], "reddish horizon toward the setting sun"
    assert noon[3][0] < 1.3 * noon[3][2], "not reddish at noon"
    assert noon[2].sum() > sunset[2].sum() > midnight[2].sum()
    assert np.allclose(midnight[2], params.night, rtol=1e-3), "night sky colour at midnight"
    zeniths = np.array([r[2] for r in rows])
    assert np.abs(np.diff(zeniths, axis=0)).max() < 0.25 * zeniths.max(), "no jumps over the day"


def test_stars_only_at_night_above_the_horizon_and_twinkle(gpu, ctx, rng):
    dirs = random_dirs(rng, 20000)
    on, off = SkySettings(star_density=0.3, twinkle=0.8), SkySettings(stars=False)
    for elevation in (45.0, 2.0, -1.0):
        s = Sun.from_angles(elevation, 30.0).direction
        assert np.array_equal(evaluate_sky(gpu, dirs, s, (1, 1, 1), on, 5.0),
                              evaluate_sky(gpu, dirs, s, (1, 1, 1), off, 5.0)), "no stars by day"
    s = Sun.from_angles(-30.0, 30.0).direction
    stars_a = evaluate_sky(gpu, dirs, s, (0, 0, 0), on, 1.0) - evaluate_sky(gpu, dirs, s, (0, 0, 0), off)
    stars_b = evaluate_sky(gpu, dirs, s, (0, 0, 0), on, 2.3) - evaluate_sky(gpu, dirs, s, (0, 0, 0), off)
    lit = (stars_a.max(axis=1) > 0) | (stars_b.max(axis=1) > 0)
    assert 0.003 < lit.mean() < 0.2
    assert not lit[dirs[:, 1] < 0].any(), "no stars below the horizon"
    assert np.abs(stars_a - stars_b)[lit].max() > 1e-2, "stars twinkle"
    assert not np.abs(stars_a - stars_b)[~lit].any(), "the sky between the stars stays put"


# -- scenes ----------------------------------------------------------------------------------------

def sky_scene(gpu, elevation, **params):
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyPlugin(**params), GroundPlugin())
    sun = Sun.from_angles(elevation, 90.0)
    sun.color, sun.ambient = (tuple(c) for c in sky_light(sun.direction))
    app.insert_resource(sun)
    app.startup()
    cam = app.resource(Camera)
    cam.position, cam.yaw, cam.pitch = np.array([0.0, 2.0, 0.0]), math.radians(80.0), 0.25
    return app


def test_scene_day_sunset_night_images(rng):
    gpu = create_headless((160, 90))
    try:
        images = {}
        for name, elevation in (("day", 50.0), ("sunset", 1.0), ("night", -30.0)):
            app = sky_scene(gpu, elevation)
            app.run_frames(2)
            assert "sky" in app.graph.dump()
            images[name] = gpu.read_pixels().astype(float)
            save_png(f"scene_{name}.png", images[name].astype(np.uint8))
            app.close()
        assert gpu.ctx.error == "GL_NO_ERROR"
    finally:
        gpu.release()
    day, sunset, night = images["day"], images["sunset"], images["night"]
    for img in (day, sunset):
        assert img.std() > 10, "not a blank image"
        sky, ground = img[:20].mean(axis=(0, 1)), img[-10:].mean(axis=(0, 1))
        assert np.abs(sky - ground).sum() > 30, "sky and ground differ"
    assert day[:20].mean(axis=(0, 1))[2] > day[:20].mean(axis=(0, 1))[0], "blue day sky"
    low = sunset[25:35].mean(axis=(0, 1))          # just above the horizon, toward the sun
    assert low[0] > 1.1 * low[2], "warm sky near the setting sun"
    top = night[:20]
    assert top.mean() < 50 and top.max() > top.mean() + 40, "dark night sky with stars"


@pytest.mark.parametrize("size", [(1, 1), (0, 0), (333, 77)])
def test_resized_and_minimized_window(size):
    gpu = create_headless((64, 36))
    try:
        app = sky_scene(gpu, -5.0)
        app.run_frames(1)
        gpu.resize(size)
        app.run_frames(2)
        img = gpu.read_pixels()
        assert img.shape[:2] == (max(1, size[1]), max(1, size[0]))
        assert gpu.ctx.error == "GL_NO_ERROR"
        app.close()
    finally:
        gpu.release()


def test_sky_day_demo_runs_headless_and_the_day_passes(tmp_path, capsys):
    code = main(["demo", "sky_day", "--headless", "--frames", "90", "--size", "96x54", "--out", str(tmp_path),
                 "--quiet"])
    assert code == 0 and "wrote 90 frames" in capsys.readouterr().out
    frames = [np.asarray(Image.open(tmp_path / f"frame_{i:05d}.png"), float) for i in (0, 45, 89)]
    assert frames[0].std() > 10, "a blank first frame"
    assert np.abs(frames[0] - frames[2]).mean() > 5, "the sky changes through the cycle"
    save_png("demo_sheet.png", np.concatenate(frames, axis=1).astype(np.uint8))


def test_stars_stay_steady_while_the_camera_pans(gpu, ctx):
    """Sub-pixel pans move each star with the camera and keep the star field's light (no flashing)."""
    size, fov = (512, 288), math.radians(60.0)
    night = Sun.from_angles(-30.0, 0.0).direction
    on, off = SkySettings(star_density=0.05, twinkle=0.0), SkySettings(stars=False)
    pixel = fov / size[1]
    cams = [Camera(yaw=0.3 + step * 0.23 * pixel, pitch=0.6, fov_y=fov) for step in range(9)]
    images = [(render_sky(gpu, c, size, on, night, (0, 0, 0)) - render_sky(gpu, c, size, off, night, (0, 0, 0)))
              [..., :3].sum(axis=-1) for c in cams]
    totals = np.array([im.sum() for im in images])
    spread = totals.std() / totals.mean()
    assert totals.min() > 0 and spread < 0.03, f"the star field's light changes by {spread:.1%} (rms) over sub-pixel pans"
    # the brightest stars well inside the frame: their centroids follow the projected directions
    first = images[0]
    inner = np.zeros_like(first, bool)
    inner[12:-12, 12:-12] = True
    peaks = [np.unravel_index(i, first.shape) for i in np.argsort(np.where(inner, first, 0).ravel())[::-1][:3000]]
    picked = []
    for y, x in peaks:      # isolated stars: nearly all the light of the 21 × 21 pixels round them is theirs
        alone = first[y - 2:y + 3, x - 2:x + 3].sum() > 0.98 * first[y - 10:y + 11, x - 10:x + 11].sum()
        if alone and all(abs(y - py) > 8 or abs(x - px) > 8 for py, px in picked):
            picked.append((y, x))
    assert len(picked) >= 6, len(picked)
    aspect = size[0] / size[1]
    errs, flicker = [], []
    for y, x in picked[:6]:
        for cam, im in zip(cams[1:], images[1:]):
            win = im[y - 5:y + 6, x - 5:x + 6]
            yy, xx = np.mgrid[y - 5:y + 6, x - 5:x + 6]
            got = np.array([(win * xx).sum(), (win * yy).sum()]) / win.sum()
            w0 = first[y - 5:y + 6, x - 5:x + 6]
            start = np.array([(w0 * xx).sum(), (w0 * yy).sum()]) / w0.sum()
            ndc = (start + 0.5) / size * 2 - 1
            direction = view_basis(cams[0], aspect) @ np.array([ndc[0], ndc[1], 1.0])
            q = np.linalg.solve(view_basis(cam, aspect), direction)
            want = ((q[:2] / q[2]) + 1) / 2 * size - 0.5
            errs.append(np.abs(got - want).max())
            flicker.append(abs(win.sum() / w0.sum() - 1.0))
    assert max(errs) < 0.05, f"stars drift off their directions by up to {max(errs):.2f} px"
    assert max(flicker) < 0.05, f"a star's light changes by up to {max(flicker):.1%} as it moves"


def test_sun_disc_has_the_real_size_a_darkened_limb_and_glare(gpu, ctx):
    sun = Sun.from_angles(30.0, 120.0).direction.astype(np.float32)
    side = unit(np.cross(sun, [0.0, 1.0, 0.0]))
    angles = np.radians(np.linspace(0.0, 2.0, 801))                 # 0 .. 2° from the centre, 0.0025° steps
    dirs = (np.cos(angles)[:, None] * sun + np.sin(angles)[:, None] * side).astype(np.float32)
    color = np.array([1.0, 0.9, 0.8])
    plain = SkySettings(stars=False, sun_gain=0.0)                  # the sky without the sun
    sky = evaluate_sky(gpu, dirs, sun, color, plain)

    def disc(**fields):
        return (evaluate_sky(gpu, dirs, sun, color, SkySettings(stars=False, **fields)) - sky) / color

    bare = disc(sun_glare=0.0)
    radius = math.degrees(angles[np.argmax(bare[:, 1] < 0.5 * SkySettings().sun_gain * LIMB_FLOOR ** 0.503)])
    assert radius == pytest.approx(0.2665, abs=0.01), "0.53° across"
    centre, edge = bare[0], bare[np.argmin(np.abs(np.degrees(angles) - 0.95 * 0.2665))]
    assert centre == pytest.approx(SkySettings().sun_gain, rel=1e-3)
    assert np.all(edge / centre < 0.75) and edge[0] / centre[0] > edge[2] / centre[2], "limb darker, bluer limb darker still"
    glare = disc()[:, 1] - bare[:, 1]
    outside = np.degrees(angles) > 0.4
    theta = np.degrees(angles[outside])
    want = 0.05 * 20.0 * (0.2665 / theta) ** 2
    assert np.allclose(glare[outside][theta < 1.0], want[theta < 1.0], rtol=0.05), "glare falls as 1/angle²"
    assert np.all(np.diff(glare[outside]) <= 1e-6), "and only falls"


def test_twilight_zenith_stays_blue(gpu, ctx):
    """Through sunset and twilight the zenith is blue (ozone's Chappuis absorption), never grey."""
    elevations = np.arange(-8.0, 10.5, 0.5)
    zenith = np.array([evaluate_sky(gpu, np.array([[0.0, 1.0, 0.0]], np.float32),
                                    Sun.from_angles(e, 90.0).direction, (0, 0, 0), SkySettings(stars=False))[0]
                       for e in elevations])
    blue = zenith[:, 2] / zenith[:, :2].max(axis=1)
    assert blue.min() > 1.5, f"the zenith greys at {elevations[np.argmin(blue)]}°: blue/max(red, green) {blue.min():.2f}"
    noon = evaluate_sky(gpu, np.array([[0.0, 1.0, 0.0]], np.float32), (0.0, 1.0, 0.0), (0, 0, 0), SkySettings())[0]
    assert np.allclose(noon, SkySettings().scale * preetham_rgb((0, 1, 0), (0, 1, 0), SkySettings().turbidity),
                       rtol=2e-3), "a zenith sun's sky is Preetham's"
