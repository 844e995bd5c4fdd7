"""No hard edge where the simulated cloud volume ends and the far field takes over (issue 12, item 4).

In the sunset and flight scenes, the clouds' coverage seen from the ground and their brightness seen
from 2 km above the layer are binned by where each pixel's ray meets the layer's middle plane,
``r = |2 uv − 1|`` in the volume's footprint (1 on its inscribed circle, where the volume has faded
out): the band just outside (the far field alone, averaged over several realisations of its pattern:
one holds some ten clouds) must agree with the volume seen at the same elevations, and no column along
the border may stand out more than the field's columns do in bands as wide wholly inside or wholly
outside (a sparse field's single bright cloud is an outlier anywhere; a seam only at the border). With
the far field switched off the outside band is empty and the tests fail. The far field's radiance per
cover matches the volume's, and its relief toward the sun adds no light. The ground shadows: the
volume's (exp(−σ · column sum)) and the far field's (exp(−column_tau · column sum at the rank)) mean
transmittance agree for the same measured cover.
"""
import math
import weakref

import numpy as np
import pytest

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
from atmos.plugins.clouds.far_field.cover import fbm_quantiles
from atmos.plugins.clouds.far_field.layer import column_tau, drift
from atmos.plugins.clouds.far_field.reference import far_optical_depth
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.sprites.plugin import CloudRenderPlugin
from atmos.plugins.clouds.shadows import CloudShadowsPlugin
from atmos.plugins.clouds.shadows.reference import shifted
from atmos.plugins.clouds import CloudSimulation
from atmos.plugins.clouds.volume.edge import edge_weight
from atmos.runner import build_app
from atmos.plugins.antialias import AntialiasPlugin

SIZE = (160, 96)
INSIDE = (0.40, 0.65)        # r: the volume at full weight
OUTSIDE = (1.0, 1.35)        # r: the far field alone
TOLERANCE = 0.35             # |far field − volume| / volume, each a band's mean of a sparse field
PER_COVER = 0.10             # the same for the radiance per cover (no pattern in it)


@pytest.fixture(scope="module")
def scenes():
    gpu = create_headless(SIZE)
    apps = {}
    try:
        yield gpu, apps
    finally:
        for app in apps.values():
            app.close()
        gpu.release()


def plugin(app, kind):
    return next(p for p in app.plugins if isinstance(p, kind))


def scene(scenes, demo, clouds="sprites"):
    """The demo's App (built with ``clouds``, the renderer, on first use; "sprites2d": the sprites with
    the march off, so the 2D far-field pass draws the far field), run 4 frames."""
    gpu, apps = scenes
    if (demo, clouds) not in apps:
        app = build_app(demo, DemoSettings(size=gpu.size, headless=True, clouds=clouds.removesuffix("2d")), gpu,
                        start=False)
        if clouds == "sprites2d":
            plugin(app, RaymarchCloudsPlugin).configure(enabled=False)
        app.startup()
        app.run_frames(4, 1 / 30)
        apps[(demo, clouds)] = app
    return apps[(demo, clouds)]


def rays(cam: Camera, size) -> np.ndarray:
    """(h, w, 3) unit view directions, first row at the top (as app.read_linear)."""
    w, h = size
    ty = math.tan(cam.fov_y / 2)
    x = (2.0 * (np.arange(w) + 0.5) / w - 1.0) * ty * w / h
    y = (1.0 - 2.0 * (np.arange(h) + 0.5) / h) * ty
    local = np.stack(np.broadcast_arrays(x[None, :], y[:, None], np.ones((h, w))), -1)
    d = local @ cam.basis().T
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def plane_radius(app, cam: Camera, reach: bool = False) -> np.ndarray:
    """(h, w) r of each pixel's hit on the layer's middle plane (inf where the ray misses it); with
    ``reach`` the hit's horizontal distance from the camera in the same unit (the footprint's half
    width: r itself for a camera over the volume's centre)."""
    layout = app.resource(CloudSimulation).sets().layout()
    mid = 0.5 * (layout.lo[1] + layout.hi[1])
    d = rays(cam, SIZE)
    s = (mid - cam.position[1]) / np.where(np.abs(d[..., 1]) > 1e-6, d[..., 1], np.nan)
    hit = cam.position[[0, 2]] + s[..., None] * d[..., [0, 2]]
    lo, hi = layout.lo[[0, 2]], layout.hi[[0, 2]]
    r = np.linalg.norm(2.0 * ((hit - cam.position[[0, 2]]) if reach else (hit - lo)) / (hi - lo) - (0.0 if reach else 1.0), axis=-1)
    return np.where(s > 0, r, np.inf)


def render(app, *, far=True, clouds=True):
    """The linear frame with the clouds (the renderer of the volume: the sprites, or the march; the far
    field the march's, volumetric, behind either, or with the march off the 2D pass) and the far field
    each on or off."""
    far_plugin, sprites, march = (plugin(app, k) for k in (CloudFarFieldPlugin, CloudRenderPlugin, RaymarchCloudsPlugin))
    renderer = march if march.settings.enabled and march.settings.volume else sprites
    far_plugin.configure(enabled=far and clouds)
    renderer.configure(enabled=clouds, **({"far_field": far} if renderer is march else {}))
    try:
        app.render()
        return app.read_linear().astype(np.float64)
    finally:
        far_plugin.configure(enabled=True)
        renderer.configure(enabled=True, **({"far_field": True} if renderer is march else {}))


def bands(metric, r, valid):
    inside = valid & (r > INSIDE[0]) & (r < INSIDE[1])
    outside = valid & (r > OUTSIDE[0]) & (r < OUTSIDE[1])
    assert inside.sum() > 100 and outside.sum() > 100, "the view holds both bands"
    return metric[inside].mean(), metric[outside].mean()


BORDER = (0.85, 1.15)         # r: where the volume gives way to the far field
ELSEWHERE = ((0.25, 0.55), (1.2, 1.5))   # bands as wide wholly inside the volume and wholly outside
OUTLIER_FACTOR = 1.5          # the border's column outlier may not exceed the field's own by more


def column_outliers(metric, r, valid, band=BORDER) -> float:
    """The largest per-column mean over ``band`` of r, in robust spreads (median absolute deviation,
    at least 5 % of the volume's own mean level r < 0.65) from the median column; inf where the band
    holds fewer than 20 columns."""
    inside = valid & (r > band[0]) & (r < band[1])
    cols = np.asarray([metric[:, c][inside[:, c]].mean() for c in range(metric.shape[1]) if inside[:, c].sum() >= 3])
    if len(cols) < 20:
        return math.inf
    floor = 0.05 * metric[valid & (r < 0.65)].mean()
    spread = max(np.median(np.abs(cols - np.median(cols))), floor, 1e-9)
    return float(np.abs(cols - np.median(cols)).max() / spread)


def seam_outliers(metric, r, valid) -> tuple[float, float]:
    """(the border band's column outlier, the largest of the same statistic over bands as wide inside
    and outside): a single bright cloud in a sparse field is as much an outlier anywhere, a seam only at
    the border."""
    return column_outliers(metric, r, valid), max(column_outliers(metric, r, valid, band) for band in ELSEWHERE)


YAWS = 0.3 + 0.5 * np.pi * np.arange(4)      # four views round the horizon: more clouds per band


def ground_view(app, yaw) -> tuple:
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 320.0, 0.0])
    cam.yaw, cam.pitch, cam.roll = yaw, math.radians(24.0), 0.0
    r = plane_radius(app, cam)
    valid = rays(cam, SIZE)[..., 1] > math.sin(math.radians(3.0))
    return r, valid


def above_view(app, yaw) -> tuple:
    cam = app.resource(Camera)
    layout = app.resource(CloudSimulation).sets().layout()
    cam.position = np.array([0.0, layout.hi[1] + 2000.0, 0.0])
    cam.yaw, cam.pitch, cam.roll = yaw, math.radians(-45.0), 0.0
    return plane_radius(app, cam), np.ones(SIZE[::-1], bool)


def behind(view):
    """``view`` with the camera moved back (horizontally) so that the volume's centre lies at the middle
    of the OUTSIDE band's reach: r is then the pixel's reach where the volume is at full weight there
    (r < INSIDE[1]), else inf: the volume seen at the elevations the far field is seen at just outside it."""
    def look(app, yaw):
        _, valid = view(app, yaw)
        cam = app.resource(Camera)
        layout = app.resource(CloudSimulation).sets().layout()
        forward = cam.basis()[[0, 2], 2] / np.linalg.norm(cam.basis()[[0, 2], 2])
        back = 0.5 * sum(OUTSIDE) * 0.5 * (layout.hi[0] - layout.lo[0])
        cam.position = cam.position - back * np.array([forward[0], 0.0, forward[1]])
        full = plane_radius(app, cam) < INSIDE[1]
        return np.where(full, plane_radius(app, cam, reach=True), np.inf), valid
    return look


def panorama(app, view, metric, **which) -> tuple:
    """(metric, r, valid) of the four views side by side: ``metric(app, image)`` per pixel."""
    parts = []
    for yaw in YAWS:
        r, valid = view(app, yaw)
        parts.append((metric(app, render(app, **which)), r, valid))
    return tuple(np.concatenate(p, axis=1) for p in zip(*parts))


def coverage(app, img):
    return np.clip(img[..., 3], 0.0, 1.0)           # the sky occlusion: the clouds' coverage


def luminance(img):
    return img[..., :3] @ np.array([0.2126, 0.7152, 0.0722])


BARE_VIEWS = weakref.WeakKeyDictionary()     # App -> {camera pose: its luminance without clouds}


def cloud_change(app, img):
    """|luminance − the same view without clouds| (the bare view rendered for the current camera, once
    per pose: the far field's seed, which the seam tests vary, draws nothing in it)."""
    cam = app.resource(Camera)
    bare = BARE_VIEWS.setdefault(app, {})
    key = (tuple(cam.position), cam.yaw, cam.pitch, cam.roll)
    if key not in bare:
        bare[key] = luminance(render(app, clouds=False))
    return np.abs(luminance(img) - bare[key])


SEEDS = range(4)              # realisations of the far field's pattern the outside band is averaged over (at most
                              # 0.26 of the volume off over the cases, TOLERANCE 0.35)


def across_the_border(app, look, metric, seeds=SEEDS) -> tuple[float, float]:
    """(the far field just outside the volume: the OUTSIDE band's mean over ``seeds`` of its pattern,
    the volume seen at the same elevations: ``behind``) for the view ``look`` and per-pixel ``metric``."""
    far = plugin(app, CloudFarFieldPlugin)
    default = far.settings.seed
    outside = []
    try:
        for seed in seeds:
            far.configure(seed=seed)
            outside.append(bands(*panorama(app, look, metric))[1])
    finally:
        far.configure(seed=default)
    return float(np.mean(outside)), bands(*panorama(app, behind(look), metric, far=False))[1]


@pytest.mark.parametrize("demo, view, clouds", [
    ("sunset", "ground", "march"), ("sunset", "above", "march"), ("flight", "ground", "march"),
    ("flight", "above", "march"), ("sunset", "above", "sprites"), ("flight", "ground", "sprites"),
    ("sunset", "above", "sprites2d"),
])
def test_clouds_have_no_step_at_the_volume_edge(scenes, demo, view, clouds):
    """From the ground: the coverage (sky occlusion); from 2 km above the layer: what the clouds change
    in luminance. The far field just outside the volume (the OUTSIDE band, averaged over SEEDS: one
    realisation of a sparse field is some ten clouds there, ±30 %) against the volume seen at the same
    elevations (camera moved back: ``behind``; a 3D field covers more of the sky nearer the horizon, so
    the band well inside, seen more steeply, is no measure of it) within TOLERANCE; and no column along
    the border more of an outlier than the field's columns are inside the volume or outside it
    (OUTLIER_FACTOR, the default seed). The march in every view; the sprite volume beside the marched
    far field from above at sunset and from the ground in flight; and the sprites with the 2D far-field
    pass (the march off)."""
    app = scene(scenes, demo, clouds)
    look, metric = (ground_view, coverage) if view == "ground" else (above_view, cloud_change)
    border, elsewhere = seam_outliers(*panorama(app, look, metric))
    outside, volume = across_the_border(app, look, metric)
    assert volume > 0.01, f"{demo}: the volume is seen ({volume:.3f})"
    assert abs(outside - volume) < TOLERANCE * volume, f"{demo} {view}: far field {outside:.3f} vs the volume {volume:.3f}"
    assert border < OUTLIER_FACTOR * elsewhere, f"{demo} {view}: column outlier {border:.1f} at the border vs {elsewhere:.1f} elsewhere"
    _, without = bands(*panorama(app, look, metric, far=False))
    assert abs(without - volume) > 0.5 * volume, "without the far field the step is there (the test can fail)"


@pytest.mark.parametrize("demo", ["sunset", "flight"])
def test_volume_and_far_field_shadows_are_as_dark_for_the_same_cover(scenes, demo):
    """Mean sun transmittance of the volume's columns (edge-weighted) vs the far field's over a tile."""
    app = scene(scenes, demo)
    far, shadows = plugin(app, CloudFarFieldPlugin), plugin(app, CloudShadowsPlugin)
    sim = app.resource(CloudSimulation)
    sets = sim.sets()
    sa, sb = (sets.maps_of(s).read_sums()[0].astype(np.float64) for s in (sets.a, sets.b))
    sums = (1.0 - sets.t) * shifted(sa, sets.a_shift) + sets.t * sb
    uv = np.stack(np.meshgrid(*((np.arange(m) + 0.5) / m for m in sums.shape), indexing="ij"), -1)
    w = edge_weight(uv, sim.settings.edge_fade)
    strength = shadows.settings.strength
    volume = float((w * np.exp(-sim.settings.sigma * strength * sums)).sum() / w.sum())
    fs = far.settings
    cover, columns = far.layer.read_cover()
    octaves = [far.layer.octaves.download(k) for k in range(4)]
    tile = far.layer.tile_size
    g = (np.arange(256) + 0.5) * 7.0 * tile / 256           # the coarsest octave repeats every φ⁴ tiles
    xz = np.stack(np.meshgrid(g, g, indexing="ij"), -1)
    tau = far_optical_depth(xz, octaves, drift(fs, sets, 0.0, tile), tile, fbm_quantiles(fs.base_frequency, fs.seed, fs.size),
                            columns, column_tau(fs, sets))
    field = float(np.exp(-strength * tau).mean())
    assert 0.1 < cover < 0.9
    assert abs(volume - field) < 0.06, f"{demo}: mean shadow transmittance {volume:.3f} (volume) vs {field:.3f} (far field)"



def radiance_per_cover(img, bare, selected) -> np.ndarray:
    """(Σ (L − (1 − a) L_bare), Σ a) over the ``selected`` pixels: what the clouds add over the bare view."""
    a = np.clip(img[..., 3], 0.0, 1.0)
    return np.array([(luminance(img) - (1.0 - a) * bare)[selected].sum(), a[selected].sum()])


def test_far_field_is_as_bright_per_cover_as_the_volume_from_above_at_sunset():
    """Against the empty sky below (terrain, fog and shafts removed), the clouds' radiance per cover,
    Σ (L − (1 − a) L_bare) / Σ a, from 2 km above: the far field just outside vs the volume well
    inside, within PER_COVER (the far field lit by the volume's own light by rank, its relief adding
    none); and that relief moves light and adds none: from above and from the ground, the far field
    alone (r 1..3) is as bright per cover with its light-march channels collapsed (light_step 0: no
    relief) within 5 % (with exp(−relief), convex, it was 1.24x and 1.31x)."""
    gpu = create_headless(SIZE)
    app = build_app("sunset", DemoSettings(size=gpu.size, headless=True, clouds="sprites"), gpu, start=False)
    try:
        plugin(app, RaymarchCloudsPlugin).configure(enabled=False)   # the 2D far field, calibrated to the sprites
        app.startup()
        plugin(app, AntialiasPlugin).configure(mode="none")      # each render alone: no history between views
        app.run_frames(4, 1 / 30)
        for name in [p.name for p in app.graph.passes if p.phase == "opaque" or p.name in ("fog", "light_shafts")]:
            app.graph.remove_pass(name)
        sprites, far_plugin = plugin(app, CloudRenderPlugin), plugin(app, CloudFarFieldPlugin)

        def far_alone():
            sprites.configure(enabled=False)
            try:
                app.render()
                return app.read_linear().astype(np.float64)
            finally:
                sprites.configure(enabled=True)

        sums = {"volume": np.zeros(2), "far": np.zeros(2)}
        for yaw in YAWS:
            r, _ = above_view(app, yaw)
            bare = luminance(render(app, clouds=False))
            sums["volume"] += radiance_per_cover(render(app, far=False), bare, (r > INSIDE[0]) & (r < INSIDE[1]))
            sums["far"] += radiance_per_cover(far_alone(), bare, (r > OUTSIDE[0]) & (r < OUTSIDE[1]))
        volume, far = (s[0] / s[1] for s in (sums["volume"], sums["far"]))
        assert sums["far"][1] > 50 and volume > 0.0
        assert abs(far - volume) < PER_COVER * volume, f"per cover: far field {far:.3f} vs volume {volume:.3f}"
        step = far_plugin.settings.light_step
        for view in (above_view, ground_view):
            got = {}
            for light_step in (step, 0.0):
                far_plugin.configure(light_step=light_step)
                total = np.zeros(2)
                for yaw in YAWS:
                    r, valid = view(app, yaw)
                    total += radiance_per_cover(far_alone(), luminance(render(app, clouds=False)), valid & (r > 1.0) & (r < 3.0))
                got[light_step] = total[0] / total[1]
            far_plugin.configure(light_step=step)
            assert abs(got[step] / got[0.0] - 1.0) < 0.05, f"{view.__name__}: the relief adds light: {got[step]:.3f} vs {got[0.0]:.3f}"
    finally:
        app.close()
        gpu.release()

def away(view, offset=(40000.0, 0.0, 0.0)):
    """``view`` with the camera moved by ``offset`` (m), r still of the volume's footprint as seen from
    the unmoved camera: the far field alone in the same geometry as the volume's bands."""
    def look(app, yaw):
        r, valid = view(app, yaw)
        cam = app.resource(Camera)
        cam.position = cam.position + np.asarray(offset)
        return r, valid
    return look


def far_alone_vs_volume(app, seeds=range(4)) -> dict:
    """Per view: (the volume's coverage in the INSIDE band, the far field's alone in the same band),
    each averaged over far-field ``seeds`` (the realisations of its pattern); opaque passes, fog and
    shafts removed so that the alpha is the clouds' own."""
    for name in [p.name for p in app.graph.passes if p.phase == "opaque" or p.name in ("fog", "light_shafts")]:
        app.graph.remove_pass(name)
    far, out = plugin(app, CloudFarFieldPlugin), {}
    for seed in seeds:
        far.configure(seed=seed)
        for name, view in (("ground", ground_view), ("above", above_view)):
            got = [bands(*panorama(app, look, coverage))[0] for look in (view, away(view))]
            out.setdefault(name, []).append(got)
    far.configure(seed=CloudFarFieldPlugin().settings.seed)
    return {name: tuple(np.mean(v, axis=0)) for name, v in out.items()}


if __name__ == "__main__":      # the radial profiles (mean of each band of r); the step the test checks (the far
    gpu = create_headless(SIZE)  # field over 8 seeds vs the volume at the same elevations); the far field alone vs
    # the volume over four seeds in the band well inside (README, "Cloud renderers")
    edges = np.array([0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.35, 1.5, 1.8])
    for demo in ("sunset", "flight"):
        for clouds in ("sprites", "march"):
            app = build_app(demo, DemoSettings(size=gpu.size, headless=True, clouds=clouds), gpu)
            app.run_frames(4, 1 / 30)
            for view, look, metric in (("ground", ground_view, coverage), ("above", above_view, cloud_change)):
                for far in (True, False):
                    v, r, ok = panorama(app, look, metric, far=far)
                    prof = [v[ok & (r > lo) & (r < hi)].mean() for lo, hi in zip(edges[:-1], edges[1:])]
                    print(demo, clouds, view, "far" if far else "nofar", " ".join(f"{p:.3f}" for p in prof))
                outside, volume = across_the_border(app, look, metric, range(8))
                print(demo, clouds, view, f"across the border: far field {outside:.3f} (8 seeds), the volume at the same "
                                          f"elevations {volume:.3f} ({outside / volume:.2f}x)")
            for view, (volume, alone) in far_alone_vs_volume(app).items():
                print(demo, clouds, view, f"coverage: volume {volume:.3f}, far field alone {alone:.3f} ({alone / volume:.2f}x)")
            app.close()
    gpu.release()
