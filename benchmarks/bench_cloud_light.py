"""Cloud light against the path tracer: error vs time of every renderer mode, and the sprite pass's
cost with the new lighting vs the old (HEAD's shaders), in one run.

Static volumes (``CloudsPlugin(density=...)``) are drawn by the sprites (downsample 1/2, LOD on/off)
and the ray march (``RaymarchCloudsPlugin.reference()`` at several step lengths) and read back with ``App.read_linear()``; the reference is
:func:`atmos.plugins.clouds.light.path_tracer.trace` of the same medium and light (``medium.environment``), all
orders (``--max-order 1``: single scattering only, against the renderers with
``ms_contribution = 0``; sky and ground light are then off too). Six views: side, from below,
toward the sun (20°), grazing sun (3°) (the goal's four), and outside the goal: toward a
low sun (10°, a sunset's silver lining; in the fit) and from above with the sun behind the camera
(40°: the backscatter a flight over the clouds sees; held out). Per view and mode: image-sum bias, relative RMSE (over pixels the
reference sees cloud in) and the frame's ms (median, ``ctx.finish`` around each frame); the tracer's
own standard error of the image sum and of the RMSE is printed beside it. Plot:
out/bench_cloud_light.png (rel. RMSE vs ms per view; the other volumes and --max-order 1 get
their own suffix) and the images, the reference then every mode per view, in
out/bench_cloud_light_images_<volume>.png. ``--fit`` searches the octaves and the diffusion field's
weight (:func:`fit`); references are cached in out/bench_cloud_light_cache/. Goal at the default real-time settings
(sprites, downsample 2, no LOD; the fit holds the march at 1-cell steps to it too): |bias| <= 10 % and
rel. RMSE <= 15 % in the issue's four views; the
sprite pass <= 1.3x the old cost.

``--grid``: the same goal on media the light was not fitted on (:func:`grid_media`): one and two
Henyey-Greenstein lobes with g 0.6 to 0.9, albedo 0.9 and 1, optical thickness 1 to 50 across the
cumulus's shape (cells sized to it at sigma_t 0.05/m: 60 m to 2.9 km across), the goal's four views,
both renderers at real-time settings, beside the bench's own fitted volumes; a Markdown table and a
heat map in out/bench_cloud_light_grid*. ``--fit-grid`` searches the octaves' scales (k_f, k_c, b,
beta; :func:`derived_light`) on chosen grid media, the rest held out.

    .venv/bin/python benchmarks/bench_cloud_light.py [--samples 256] [--volume ellipsoid] [--max-order 1]
    .venv/bin/python benchmarks/bench_cloud_light.py --grid [--size 96x64 --samples 64] [--only "HG .9"]
"""
from __future__ import annotations

import argparse
import hashlib
import math
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from atmos import App, DefaultPlugins, create_headless
from atmos.camera import Camera, view_basis
from atmos.gpu import add_shader_path
from atmos.lighting import Sun
from atmos.phase import Phase
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.raymarch.settings import REFERENCE
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.volume.light import DEFAULT_DIFFUSION, DEFAULT_OCTAVES, sun_light
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.clouds.light.ground import ground_sun_of
from atmos.plugins.clouds.light.medium import environment, phase_octaves
from atmos.plugins.clouds.light.path_tracer import trace

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "out"
SIZE = (96, 64)
BASE = 500.0
SKY = (0.3, 0.4, 0.6)


def unit_grid(shape):
    return np.meshgrid(*[(np.arange(k) + 0.5) / k for k in shape], indexing="ij")


def ellipsoid():
    """The comparison volume of issue 12: a smooth ellipsoid, cubic 20 m cells, sigma_t 0.02/m."""
    x, y, z = unit_grid((24, 12, 24))
    d = np.clip(1.0 - ((x - .5) ** 2 / 0.12 + (y - .5) ** 2 / 0.1 + (z - .5) ** 2 / 0.12) * 4, 0, None)
    return d.astype(np.float32), (20.0, 20.0, 20.0), 0.02


def cumulus(scale: int = 1):
    """A lumpy, denser cloud with a flat base on non-cubic cells (20 x 12 x 20 m), sigma_t 0.05/m;
    ``scale``: the same shape on ``scale`` times as many cells per axis, each ``1 / scale`` the size."""
    x, y, z = unit_grid((24 * scale, 16 * scale, 24 * scale))
    rng = np.random.default_rng(7)
    d = np.zeros_like(x)
    for _ in range(9):
        c = rng.uniform([0.3, 0.25, 0.3], [0.7, 0.55, 0.7])
        r = rng.uniform(0.12, 0.22)
        d = np.maximum(d, 1.0 - ((x - c[0]) ** 2 + ((y - c[1]) * 1.3) ** 2 + (z - c[2]) ** 2) / r ** 2)
    d *= np.clip((y - 0.1) / 0.1, 0.0, 1.0)             # the flat base
    return np.clip(d, 0.0, 1.0).astype(np.float32), (20.0 / scale, 12.0 / scale, 20.0 / scale), 0.05


VOLUMES = {"ellipsoid": ellipsoid, "cumulus": cumulus}
MODES = {   # label: (sprite fields, None) or ({}, reference-march fields: the step in cells)
    "sprites 1/2": (dict(downsample=2), None),                 # the default real-time settings
    "sprites 1/2 LOD": (dict(downsample=2, lod_pixels=4.0), None),
    "sprites 1/1": (dict(downsample=1), None),
    "sprites 1/1 LOD": (dict(downsample=1, lod_pixels=4.0), None),
    "march 1 cell": ({}, dict(step=1.0)), "march 1/2 cell": ({}, dict(step=0.5)),
    "march 1/4 cell": ({}, {}), "march 1/8 cell": ({}, dict(step=0.125)),        # {}: the reference's step
}


FRAMING = 0.8 / 1.9     # the views' distances in units of the volume's largest side, over the old ones


def views(lo, hi):
    """name: (camera position, target, sun elevation in degrees; the sun's azimuth is 90: toward +x).
    The cloud fills most of the frame (FRAMING): from 1.9 sides away the cumulus covered ~600 of
    192x128's pixels, so its error measured the sprites' edge resampling more than the light."""
    c = (lo + hi) / 2
    r = float(np.max(hi - lo)) * FRAMING
    return {"side": (c + [0, 0, 1.9 * r], c, 90.0), "below": (c + [0, -1.25 * r, 0.6 * r], c, 90.0),
            "toward sun": (c + [-1.7 * r, -0.2 * r, 0], c, 20.0), "toward low sun": (c + [-1.7 * r, -0.2 * r, 0], c, 10.0),
            "grazing": (c + [0, 0.1 * r, 1.9 * r], c, 3.0), "sun behind": (c + [1.3 * r, 1.3 * r, 0], c, 40.0)}


class Scene:
    """One App drawing a static volume with both renderers, switched per mode."""

    def __init__(self, gpu, volume, single: bool, extra=(), **medium):
        """``extra``: more plugins for the App (e.g. a MeshPlugin); ``medium``: more CloudSettings
        fields (``albedo``, ``phase``)."""
        density, cell, sigma_t = volume
        if single:
            medium.update(sky_intensity=0.0, ground_albedo=0.0)
        self.settings = CloudSettings(cell_size=cell, base_altitude=BASE, sigma_t=sigma_t, group_size=(8, 8),
                                      smoothing_slices=1, **medium)
        self.render_fields = dict(ms_contribution=0.0, ms_diffusion=0.0) if single else {}
        self.renderer = CloudRenderPlugin(**self.render_fields)
        self.march = RaymarchCloudsPlugin.reference(enabled=False, **self.render_fields)
        self.clouds = CloudsPlugin(self.settings, density=density)
        self.app = App(gpu).add_plugins(DefaultPlugins(overlay=False), self.clouds,
                                        self.renderer, self.march, *extra)
        self.app.startup()
        self.density, self.cell, self.sigma_t = density, cell, sigma_t
        self.lo = np.array([0.0, BASE, 0.0])
        self.hi = self.lo + np.array(density.shape) * np.array(cell)

    def look(self, position, target, elevation):
        sun = Sun.from_angles(elevation, 90.0)
        sun.ambient = SKY
        self.app.insert_resource(sun)
        cam = self.app.resource(Camera)
        cam.position = np.asarray(position, float)
        cam.look_at(np.asarray(target, float))
        cam.near, cam.far = 1.0, 20000.0
        return cam, sun

    def mode(self, fields, march, light=None):
        """A MODES entry; ``light``: octave and field settings for both renderers (None: the defaults)."""
        light = {**self.render_fields, **(light or {})}
        self.renderer.configure(enabled=march is None, **{**dict(downsample=2, lod_pixels=None), **light, **fields})
        self.march.configure(enabled=march is not None, **{"step": REFERENCE["step"], **light, **(march or {})})

    def frame_ms(self, frames=7) -> float:
        ctx, times = self.app.gpu.ctx, []
        for _ in range(frames + 1):
            ctx.finish()
            start = time.perf_counter()
            self.app.render()
            ctx.finish()
            times.append(time.perf_counter() - start)
        return float(np.median(times[1:]) * 1e3)

    def ground_sun(self) -> float:
        """G, the ground's mean sun transmittance under the clouds the renderers light their bases
        with (:mod:`atmos.plugins.clouds.light.ground`): the reference's ground takes it too."""
        return ground_sun_of(self.clouds.simulation.sets())

    def reference(self, cam, sun, samples, max_order):
        w, h = SIZE
        xs = 2 * (np.arange(w) + 0.5) / w - 1
        ys = 1 - 2 * (np.arange(h) + 0.5) / h
        d = np.stack(np.broadcast_arrays(xs[None, :], ys[:, None], 1.0), -1).reshape(-1, 3) @ view_basis(cam, w / h).T
        color, ambient = sun_light(sun)
        direction = np.asarray(sun.direction, float) / np.linalg.norm(sun.direction)
        e, sky, ground = environment(self.settings, color, ambient, direction, ground_sun=self.ground_sun())
        s = self.settings
        start = time.perf_counter()
        r = trace(self.density, self.cell, self.lo, np.broadcast_to(cam.position, d.shape), d, sigma_t=self.sigma_t,
                  albedo=s.albedo, g=s.phase.g, g2=s.phase.g2, w=s.phase.w, sun_dir=direction, sun_irradiance=e,
                  sky=sky, ground=ground, samples=samples, max_order=max_order, rng=np.random.default_rng(1))
        return r.radiance.reshape(h, w, 3), r.radiance_error.reshape(h, w, 3), time.perf_counter() - start


OCTAVE_FIELDS = ("ms_attenuation", "ms_contribution", "ms_eccentricity")


def cached_reference(scene, cam, sun, samples, max_order=None):
    """:meth:`Scene.reference` (radiance, its standard error, the trace's seconds), kept in
    out/bench_cloud_light_cache/ under a hash of everything it depends on (volume, medium, camera, the ground's G,
    sun, size, samples, orders)."""
    key = hashlib.sha1(b"".join([scene.density.tobytes(), repr((scene.cell, scene.sigma_t, scene.settings, SIZE,
                                 samples, max_order, tuple(cam.position), cam.yaw, cam.pitch, cam.roll, cam.fov_y,
                                 tuple(sun.direction), tuple(sun.color), tuple(sun.ambient),
                                 round(scene.ground_sun(), 6))).encode()])).hexdigest()
    path = OUT / "bench_cloud_light_cache" / f"{key[:20]}.npz"
    if path.exists():
        with np.load(path) as f:
            return f["radiance"], f["error"], float(f["seconds"])
    ref, err, seconds = scene.reference(cam, sun, samples, max_order)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".part.npz")
    np.savez(tmp, radiance=ref, error=err, seconds=seconds)
    tmp.replace(path)                       # never a half-written cache file
    return ref, err, seconds


def errors(image, ref):
    """(image-sum bias, relative RMSE over the pixels with cloud in the reference)."""
    rgb = np.asarray(image, np.float64)[..., :3]
    mask = ref.sum(-1) > 1e-3 * ref.sum(-1).max()
    bias = rgb.sum() / ref.sum() - 1.0
    rmse = math.sqrt(((rgb - ref) ** 2).sum(-1)[mask].mean() / (ref ** 2).sum(-1)[mask].mean())
    return bias, rmse


def less_noise(rmse: float, noise: float) -> float:
    """A rel. RMSE less the tracer's own (independent errors add in quadrature)."""
    return math.sqrt(max(rmse ** 2 - noise ** 2, 0.0))


def tracer_noise(ref, err):
    """The reference's own standard error: of its image sum (relative) and its rel. RMSE floor."""
    mask = ref.sum(-1) > 1e-3 * ref.sum(-1).max()
    return (math.sqrt((err ** 2).sum()) / ref.sum(),
            math.sqrt((err ** 2).sum(-1)[mask].mean() / (ref ** 2).sum(-1)[mask].mean()))


# -- the old lighting: HEAD's shaders in a temporary directory on the search path ------------------
OLD_FILES = ("clouds/sprites/sprite.vert", "clouds/sprites/sprite.frag", "clouds/volume/volume.glsl")


def old_program(gpu, directory: Path):
    """HEAD's sprite program, its sprite and volume includes pointed at the copies (prefix "old")."""
    for name in OLD_FILES:
        text = subprocess.run(["git", "show", f"HEAD:shaders/{name}"], cwd=ROOT, check=True,
                              capture_output=True, text=True).stdout
        text = re.sub(r'#include "clouds/(sprites|volume)/', r'#include "old/clouds/\1/', text)
        (directory / name).parent.mkdir(parents=True, exist_ok=True)
        (directory / name).write_text(text)
    add_shader_path(directory, prefix="old")
    return gpu.program(vertex_shader="old/clouds/sprites/sprite.vert", fragment_shader="old/clouds/sprites/sprite.frag")


COST_SIZE = (640, 360)


def sprite_pass_cost(rounds=5, frames=9):
    """Median GPU ms of the "cloud_render" pass at 640x360 (the ellipsoid filling the side view,
    downsample 2), the new program and HEAD's alternated in one App; the old one's sun_color and
    ambient set as HEAD's Python set them."""
    gpu = create_headless(COST_SIZE)
    scene = Scene(gpu, ellipsoid(), False)
    app = scene.app
    sprite = next(p for p in app.graph.passes if p.name == "cloud_render")
    scene.mode({}, None)
    pos, target, elevation = views(scene.lo, scene.hi)["side"]
    scene.look(target + (pos - target) * 0.6, target, elevation)
    app.render()
    new = sprite.program
    with tempfile.TemporaryDirectory() as tmp:
        old = old_program(gpu, Path(tmp))
        color, ambient = sun_light(app.resource(Sun))
        for name, value in (("sun_color", color), ("ambient", ambient)):
            if name in old:                 # HEAD's shaders before the radiometric light had these
                old[name].value = value
        app.graph.timings_enabled = True
        ms = {"new": [], "old": []}
        for _ in range(rounds):
            for label, program in (("new", new), ("old", old)):
                sprite.program = program
                sprite._release_buffers()           # its vertex array belongs to one program
                for i in range(frames):
                    app.render()
                    gpu.ctx.finish()
                    t = app.graph.timings.get("cloud_render")
                    if t and i >= 3:                # results lag a frame or two: skip the other's
                        ms[label].append(t[0])
        sprite.program = new
        sprite._release_buffers()
        app.graph.timings_enabled = False
    app.close()
    gpu.release()
    return {k: float(np.median(v)) for k, v in ms.items()}


FIT_FIELDS = OCTAVE_FIELDS + ("ms_diffusion",)
FIT_START = (0.25, DEFAULT_OCTAVES[1], 0.875, DEFAULT_DIFFUSION)     # a and c as last fitted fixed, b and beta the defaults
FIT_STEPS = (0.1, 0.1, 0.1, 0.2)
FIT_LIMITS = ((0.0, 1.0), (0.0, 1.0), (0.0, 1.0), (0.0, 2.0))


FIT_MODES = ("sprites 1/2", "march 1 cell")      # both renderers at real-time settings
FIT_VIEWS = ("side", "below", "toward sun", "grazing", "toward low sun")   # the goal's and the low sun; the sun behind is held out


def fit_cases(gpu, media, views_, samples):
    """(scene, look, reference, its RMSE noise, label, mode) for each medium (label: (volume, CloudSettings
    fields)), view and FIT_MODES mode, the references cached."""
    cases = []
    for label, (volume, medium) in media.items():
        scene = Scene(gpu, volume, False, **medium)
        for view in views_:
            pos, target, elevation = views(scene.lo, scene.hi)[view]
            cam, sun = scene.look(pos, target, elevation)
            ref, err, _ = cached_reference(scene, cam, sun, samples)
            for m in FIT_MODES:
                cases.append((scene, (pos, target, elevation), ref, tracer_noise(ref, err)[1], f"{label}/{view}/{m}", m))
    return cases


def fit(cases, light_of, start, steps, limits, rounds=8):
    """Coordinate search of the values ``light_of(values, cloud_settings)`` turns into the renderers'
    light fields, against the ``cases`` (:func:`fit_cases`): each round tries a step down and up per
    value and keeps the first that lowers the score: per case the larger of |bias| / 10 % and rel. RMSE
    less tracer noise / 15 % (1: the goal), over the cases their 8-norm (nearly the worst, but a tie
    goes to the better rest), halving the steps after a round with no gain. Prints each gain and
    returns the best values."""
    def score(values):
        errs = []
        for scene, look, ref, noise, _, m in cases:
            scene.look(*look)
            scene.mode(*MODES[m], light=light_of(values, scene.settings))
            bias, rmse = errors(scene.app.read_linear(), ref)
            errs.append((bias, less_noise(rmse, noise)))
        return sum(max(abs(b) / 0.10, r / 0.15) ** 8 for b, r in errs) ** 0.125, errs

    def show(values, result):
        print(f"{tuple(round(v, 4) for v in values)}: score {result[0]:.3f}; " + ", ".join(
            f"{c[4]} {100 * b:+.1f}/{100 * r:.1f}%" for (b, r), c in zip(result[1], cases)), flush=True)

    values, steps = list(start), list(steps)
    best = score(values)
    show(values, best)
    for _ in range(rounds):
        gained = False
        for i, (lo, hi) in enumerate(limits):
            for sign in (-1.0, 1.0):
                trial = list(values)
                trial[i] = min(max(trial[i] + sign * steps[i], lo), hi)
                result = None if trial == values else score(trial)
                if result is not None and result[0] < best[0]:
                    values, best, gained = trial, result, True
                    show(values, best)
                    break
        if not gained:
            steps = [v / 2 for v in steps]
    for scene in {id(c[0]): c[0] for c in cases}.values():
        scene.app.close()
    return tuple(values)


def fixed_light(values, settings) -> dict:
    """The renderers' four light fields as given, whatever the medium."""
    return dict(zip(FIT_FIELDS, values))


DERIVED_START, DERIVED_STEPS = (1.0, 1.0, 0.95, 0.575), (0.1, 0.1, 0.05, 0.2)
DERIVED_LIMITS = ((0.0, 1.5), (0.0, 1.5), (0.0, 1.0), (0.0, 2.0))


def derived_light(values, settings) -> dict:
    """(k_f, k_c, b, beta): the octaves' a and c from the medium's phase
    (:func:`atmos.plugins.clouds.light.medium.phase_octaves` at these scales; the renderers weigh them by
    the albedo)."""
    k_f, k_c, b, beta = values
    a, c = phase_octaves(settings.phase, (k_f, k_c))
    return dict(ms_attenuation=a, ms_contribution=b, ms_eccentricity=c, ms_diffusion=beta)


# -- the held-out grid: media the light was not fitted on -------------------------------------------
GRID_PHASES = {"HG .6": Phase(0.6, 0.0, 0.0), "HG .8": Phase(0.8, 0.0, 0.0), "HG .9": Phase(0.9, 0.0, 0.0),
               "2 lobes .6": Phase(0.6, -0.3, 0.2), "2 lobes .9": Phase(0.9, -0.4, 0.1)}
GRID_ALBEDOS = (0.9, 1.0)
GRID_TAUS = (1.0, 5.0, 20.0, 50.0)
GRID_VIEWS = ("side", "below", "toward sun", "grazing")
FIT_MEDIA = ("fitted: cumulus", "fitted: ellipsoid")     # the bench's own volumes and default medium, what --fit scores


def diameter_tau(volume) -> float:
    """The optical thickness of a volume's horizontal (x) diameter through its middle."""
    density, cell, sigma_t = volume
    ny, nz = density.shape[1], density.shape[2]
    mid = density[:, (ny - 1) // 2:ny // 2 + 1, (nz - 1) // 2:nz // 2 + 1].astype(np.float64).mean((1, 2))
    return float(sigma_t * mid.sum() * cell[0])


def grid_volume(tau: float):
    """The cumulus's shape on twice its cells per axis (48 x 32 x 48, so one cell's optical thickness
    stays below 3.1 at tau 50), sigma_t 0.05/m as in a real cumulus, its cells sized so that
    :func:`diameter_tau` is ``tau``: about 60 m across at tau 1, 2.9 km at tau 50."""
    density, cell, sigma_t = cumulus(2)
    k = tau / diameter_tau((density, cell, sigma_t))
    return density, tuple(c * k for c in cell), sigma_t


def grid_media():
    """label: (volume, CloudSettings fields): the fitted media first, then the held-out grid."""
    media = {"fitted: cumulus": (cumulus(), {}), "fitted: ellipsoid": (ellipsoid(), {})}
    for pname, phase in GRID_PHASES.items():
        for albedo in GRID_ALBEDOS:
            for tau in GRID_TAUS:
                media[f"{pname}, albedo {albedo:g}, tau {tau:g}"] = (grid_volume(tau), dict(albedo=albedo, phase=phase))
    return media


def run_grid(gpu, samples, modes=FIT_MODES, light_of=None, only=None):
    """Every medium of :func:`grid_media` (``only``: labels containing this; ``light_of(settings)``: the
    renderers' light fields for a medium, None: their defaults) in GRID_VIEWS against
    cached all-order references: rows (medium, tau, view, {mode: (bias, rel. RMSE less the tracer's
    noise)}) and {medium: {mode: frame ms}} (the side view)."""
    rows, ms = [], {}
    for label, (volume, medium) in grid_media().items():
        if only and only not in label:
            continue
        scene = Scene(gpu, volume, False, **medium)
        tau = diameter_tau(volume)
        ms[label] = {}
        for view in GRID_VIEWS:
            pos, target, elevation = views(scene.lo, scene.hi)[view]
            cam, sun = scene.look(pos, target, elevation)
            ref, err, _ = cached_reference(scene, cam, sun, samples)
            noise = tracer_noise(ref, err)[1]
            result = {}
            for m in modes:
                scene.mode(*MODES[m], light=light_of(scene.settings) if light_of else None)
                bias, rmse = errors(scene.app.read_linear(), ref)
                result[m] = (bias, less_noise(rmse, noise))
                if view == "side":
                    ms[label][m] = scene.frame_ms(3)
            rows.append((label, tau, view, result))
            print(f"{label:34s} {view:11s} " + "  ".join(f"{m} {100 * b:+6.1f}% {100 * r:5.1f}%{'' if inside(b, r) else ' x'}"
                                                       for m, (b, r) in result.items()), flush=True)
        scene.app.close()
    return rows, ms


def inside(bias: float, rmse: float) -> bool:
    """The goal: image-sum bias within +-10 %, rel. RMSE (less the tracer's noise) <= 15 %."""
    return abs(bias) <= 0.10 and rmse <= 0.15


def grid_index(rows):
    """(the media in order, {(medium, view): {mode: (bias, RMSE)}}) of :func:`run_grid`'s rows."""
    return list(dict.fromkeys(r[0] for r in rows)), {(r[0], r[2]): r[3] for r in rows}


def grid_report(rows, ms, modes) -> str:
    """The grid as a Markdown table (one row per medium: bias / RMSE per view and mode, ms beside) and a
    summary per mode, the fitted media and the held-out ones apart."""
    media, by = grid_index(rows)
    lines = ["| medium | τ | renderer | " + " | ".join(GRID_VIEWS) + " | frame ms |", "|---|---|---|" + "---|" * (len(GRID_VIEWS) + 1)]
    for label in media:
        tau = next(r[1] for r in rows if r[0] == label)
        for m in modes:
            cells = []
            for view in GRID_VIEWS:
                b, r = by[(label, view)][m]
                cells.append(f"{100 * b:+.1f} / {100 * r:.1f}" + ("" if inside(b, r) else " ✗"))
            lines.append(f"| {label} | {tau:.1f} | {m} | " + " | ".join(cells) + f" | {ms[label].get(m, float('nan')):.1f} |")
    lines.append("")
    for part, keep in (("fitted", lambda lab: lab in FIT_MEDIA), ("held out", lambda lab: lab not in FIT_MEDIA)):
        for m in modes:
            cells = [by[(lab, v)][m] for lab in media if keep(lab) for v in GRID_VIEWS]
            if not cells:
                continue
            good = sum(inside(b, r) for b, r in cells)
            worst_b = max(cells, key=lambda c: abs(c[0]))[0]
            worst_r = max(c[1] for c in cells)
            score = np.median([max(abs(b) / 0.10, r / 0.15) for b, r in cells])
            lines.append(f"{part}, {m}: {good}/{len(cells)} cells inside the goal; worst bias {100 * worst_b:+.1f} %, "
                         f"worst rel. RMSE {100 * worst_r:.1f} %; median score {score:.2f} (max(|bias| / 10 %, "
                         f"RMSE / 15 %): 1 is the goal's edge)")
    return "\n".join(lines)


def grid_plot(rows, modes, path):
    """One heat map per renderer: the score max(|bias| / 10 %, RMSE / 15 %) per medium (rows) and view
    (columns); <= 1 is inside the goal."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    media, by = grid_index(rows)
    fig, axes = plt.subplots(1, len(modes), figsize=(5.2 * len(modes), 0.28 * len(media) + 1.6), squeeze=False)
    for ax, m in zip(axes[0], modes):
        score = np.array([[max(abs(by[(lab, v)][m][0]) / 0.10, by[(lab, v)][m][1] / 0.15) for v in GRID_VIEWS]
                          for lab in media])
        ax.imshow(np.minimum(score, 3.0), cmap="RdYlGn_r", vmin=0.0, vmax=2.0, aspect="auto")
        for (i, j), v in np.ndenumerate(score):
            ax.text(j, i, f"{v:.2f}", ha="center", va="center", fontsize=6)
        ax.set_xticks(range(len(GRID_VIEWS)), GRID_VIEWS, fontsize=7)
        ax.set_yticks(range(len(media)), media, fontsize=6)
        ax.set_title(f"{m}: max(|bias|/10%, RMSE/15%)", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot(table, path):
    import matplotlib
    import matplotlib.ticker
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = list(next(iter(table.values())).keys())
    fig, axes = plt.subplots(1, len(names), figsize=(4 * len(names), 3.6), squeeze=False)
    for ax, view in zip(axes[0], names):
        for mode, per_view in table.items():
            bias, rmse, ms = per_view[view]
            ax.scatter(ms, 100 * rmse, label=mode, marker="o" if mode.startswith("sprites") else "s")
        ax.axhline(15, color="grey", lw=0.8, ls="--")
        ax.set_title(view)
        ax.set_xlabel("frame ms (llvmpipe)")
        ax.set_ylabel("rel. RMSE %")
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def strip(images, path):
    """One row per view: the reference then each mode, tone-mapped with one exposure per row (the
    99th percentile of the reference's cloud pixels at 0.8)."""
    from PIL import Image

    from atmos.render_core import tone_map
    rows = []
    for row in images:
        lit = row[0][row[0].sum(-1) > 0]
        exposure = 0.8 / max(float(np.percentile(lit, 99)) if len(lit) else 1.0, 1e-6)
        rows.append(np.concatenate([tone_map(im[..., :3], exposure) for im in row], 1))
    Image.fromarray((np.concatenate(rows, 0) * 255).astype(np.uint8)).save(path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=None, help="path-tracer samples per pixel (256; --grid: 96)")
    ap.add_argument("--max-order", type=int, default=None, help="1: single scattering only")
    ap.add_argument("--volume", choices=[*VOLUMES, "all"], default="all")
    ap.add_argument("--modes", default=",".join(MODES), help="comma-separated mode labels")
    ap.add_argument("--size", default=None, help="image size WxH (192x128; --grid: 72x48)")
    ap.add_argument("--grid", action="store_true", help="the held-out grid of media (phase, albedo, optical "
                    "thickness) in the goal's four views, both renderers at real-time settings")
    ap.add_argument("--only", default=None, help="--grid: only the media whose label contains this")
    ap.add_argument("--grid-model", default=None, help='--grid with derived_light("k_f,k_c,b,beta") in place of '
                    "the renderers' defaults")
    ap.add_argument("--fit-grid", default=None, help="fit the octaves as derived from the medium (derived_light) "
                    "to the grid media whose labels contain any of these ;-separated strings")
    ap.add_argument("--fit", action="store_true", help="fit the octaves and the field's weight to the references")
    ap.add_argument("--fit-start", default=None, help='where the search starts: "a,b,c,beta" (default FIT_START)')
    ap.add_argument("--no-cost", action="store_true", help="skip the old-vs-new sprite pass timing")
    args = ap.parse_args(argv)
    global SIZE
    SIZE = tuple(int(v) for v in (args.size or ("72x48" if args.grid else "192x128")).lower().split("x"))
    args.samples = args.samples or (96 if args.grid else 256)
    gpu = create_headless(SIZE)
    if args.fit_grid:
        keys = args.fit_grid.split(";")
        media = {k: v for k, v in grid_media().items() if any(key in k for key in keys)}
        start = DERIVED_START if args.fit_start is None else tuple(float(v) for v in args.fit_start.split(","))
        return fit(fit_cases(gpu, media, GRID_VIEWS, args.samples), derived_light, start, DERIVED_STEPS, DERIVED_LIMITS)
    if args.grid:
        OUT.mkdir(exist_ok=True)
        model = None if args.grid_model is None else tuple(float(v) for v in args.grid_model.split(","))
        rows, ms = run_grid(gpu, args.samples, only=args.only,
                            light_of=None if model is None else lambda settings: derived_light(model, settings))
        report = grid_report(rows, ms, FIT_MODES)
        print("\n" + report)
        tag = (f"_{args.only.replace(' ', '_').replace(',', '')}" if args.only else "") + ("_model" if model else "")
        (OUT / f"bench_cloud_light_grid{tag}.md").write_text(report + "\n")
        grid_plot(rows, FIT_MODES, OUT / f"bench_cloud_light_grid{tag}.png")
        gpu.release()
        return rows
    single = args.max_order == 1
    if args.fit:
        start = FIT_START if args.fit_start is None else tuple(float(v) for v in args.fit_start.split(","))
        if len(start) != len(FIT_FIELDS):
            ap.error(f"--fit-start takes {len(FIT_FIELDS)} comma-separated values ({', '.join(FIT_FIELDS)}); "
                     f"got {len(start)}")
        media = {name: (make(), {}) for name, make in VOLUMES.items()}
        return fit(fit_cases(gpu, media, FIT_VIEWS, args.samples), fixed_light, start, FIT_STEPS, FIT_LIMITS)
    modes = [m.strip() for m in args.modes.split(",")]
    OUT.mkdir(exist_ok=True)
    summary = {}
    for vname in (VOLUMES if args.volume == "all" else [args.volume]):
        scene = Scene(gpu, VOLUMES[vname](), single)
        table = {m: {} for m in modes}
        images = []
        print(f"\n{vname}: shape {scene.density.shape}, cells {scene.cell} m, sigma_t {scene.sigma_t}/m, "
              f"{SIZE[0]}x{SIZE[1]} px, tracer {args.samples} spp, max_order {args.max_order}")
        print(f"{'view':11s} {'mode':16s} {'bias':>7s} {'rel RMSE':>9s} {'frame ms':>9s} {'RMSE less tracer noise':>23s}")
        for view, (pos, target, elevation) in views(scene.lo, scene.hi).items():
            cam, sun = scene.look(pos, target, elevation)
            ref, err, seconds = cached_reference(scene, cam, sun, args.samples, args.max_order)
            noise_sum, noise_rmse = tracer_noise(ref, err)
            print(f"{view:11s} {'path tracer':16s} ±{100 * noise_sum:5.1f}% {100 * noise_rmse:8.1f}% "
                  f"{1e3 * seconds:9.0f}   (its standard error; time of the whole trace)")
            row = [ref]
            for m in modes:
                scene.mode(*MODES[m])
                image = scene.app.read_linear()
                bias, rmse = errors(image, ref)
                ms = scene.frame_ms()
                table[m][view] = (bias, rmse, ms)
                row.append(image)
                clean = less_noise(rmse, noise_rmse)
                print(f"{'':11s} {m:16s} {100 * bias:+6.1f}% {100 * rmse:8.1f}% {ms:9.2f} {100 * clean:22.1f}%")
            images.append(row)
        tag = f"{vname}{'_single' if single else ''}"
        strip(images, OUT / f"bench_cloud_light_images_{tag}.png")
        plot(table, OUT / f"bench_cloud_light{'' if vname == 'ellipsoid' and not single else '_' + tag}.png")
        summary[vname] = table
        scene.app.close()
    gpu.release()
    if not args.no_cost:
        cost = sprite_pass_cost()
        print(f"\nsprite pass GPU ms ({COST_SIZE[0]}x{COST_SIZE[1]}, side view, downsample 2): new {cost['new']:.2f}, "
              f"old (HEAD's shaders) {cost['old']:.2f}: {cost['new'] / cost['old']:.2f}x (goal <= 1.3x)")
    return summary


if __name__ == "__main__":
    main(sys.argv[1:])
