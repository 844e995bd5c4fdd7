"""The ray-marched clouds (issue 15) measured in one run, beside the sprites:

1. **Error vs time** against the path tracer (bench_cloud_light's two static volumes, six views,
   references and error metrics): the march at steps 32–256 (full resolution), resolution 1/2/4 with
   and without reprojection (with it, the image after r² + 4 frames of a still camera), detail
   octaves 1–3 — their "truth" is another cloud, so those rows give the change vs octaves 0, not the
   error vs the tracer — and the default sprites (downsample 2): bias, rel. RMSE, RMSE less the
   tracer's noise, frame ms (median, glFinish around each). Plot out/bench_cloud_raymarch.png,
   images out/bench_cloud_raymarch_images_<volume>.png (reference, then every row).
2. **The sunset frame at 1024×768** with each renderer in one App (both plugins, one enabled at a
   time, alternated in rounds): median frame ms (glFinish), the cloud pass's own ms from the render
   graph's timer queries, the ratio march / sprites.
3. **Temporal stability**: still camera, frozen clouds (a static volume, ``App.render`` does not
   advance time): mean |Δ| of the HDR colour frame to frame over 32 frames, in units of the mean cloud
   radiance, for r 1, 2 with and without reprojection, 4 with. Plot out/bench_cloud_raymarch_stability.png.
4. **Ghosting after a fast turn**: converged at one view, the camera turns 20° (past the default
   ``motion_limit``) or 5° (within it) in one frame and holds;
   per frame after the turn the error vs the converged image at the new view (mean |Δ| and its 99th
   percentile, the same units) for ``history_clamp`` × ``motion_limit`` (jitter off, so the converged
   image is exact and the error is the ghost alone). Plot out/bench_cloud_raymarch_ghost_<turn>deg.png; frames
   1 and 4 after the turn, the converged one, then |frame 1 − converged| and |frame 4 − converged|
   (white = 25 % of the mean cloud radiance) in out/cloud_temporal_ghost_<turn>deg_<clamp>_<limit>.png.
5. **Ghosting after scene motion, still camera**: the clouds drift (the static volume's origin moves
   0.5 and 3 px per frame), only the detail noise scrolls with the wind, or a box crosses in front
   (4 px per frame); per frame the error vs the resolution-1 march of the same frame (mean |Δ| and
   p99, the same units) for r2 and r4 reprojection and the r2 upsample; frames in
   out/cloud_temporal_ghost_<case>_<row>.png.

On llvmpipe only the ratios of times inside one run mean anything. The tables also go to
out/bench_cloud_raymarch_<W>x<H>.txt. References are cached in out/cache/ keyed by everything they
depend on (the shading modules' source included).

    .venv/bin/python benchmarks/bench_cloud_raymarch.py [--quick] [--size 192x128] [--samples 128]
        [--only error sunset stability ghost events]
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bench_cloud_light as light  # noqa: E402  (its volumes, views, references and metrics)

from atmos import create_headless  # noqa: E402
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin  # noqa: E402
from atmos.plugins.clouds.raymarch.settings import REFERENCE  # noqa: E402
from atmos.plugins.clouds.sprites import CloudRenderPlugin  # noqa: E402

ROOT = HERE.parent
OUT = ROOT / "out"
PARTS = ("error", "sunset", "stability", "ghost", "events")
DEFAULT = dict(steps=256, resolution=2, reprojection=True, detail_octaves=0, jitter=True,
               history_clamp=RaymarchCloudsPlugin.settings_class.history_clamp,
               motion_limit=RaymarchCloudsPlugin.settings_class.motion_limit)
REAL_TIME = {name: getattr(RaymarchCloudsPlugin.settings_class, name) for name in REFERENCE}   # the defaults
ROWS = {    # label: march fields over DEFAULT (None: the default sprites, downsample 2)
    "sprites 1/2": None,
    "march 32 r1": dict(steps=32, resolution=1), "march 64 r1": dict(steps=64, resolution=1),
    "march 128 r1": dict(steps=128, resolution=1), "march 256 r1": dict(steps=256, resolution=1),
    "march r2 reproj": {}, "march r4 reproj": dict(resolution=4),
    "march r2 upsample": dict(reprojection=False), "march r4 upsample": dict(resolution=4, reprojection=False),
    "march r2 oct 1": dict(detail_octaves=1), "march r2 oct 2": dict(detail_octaves=2),
    "march r2 oct 3": dict(detail_octaves=3),
}
QUICK_ROWS = ("sprites 1/2", "march 64 r1", "march r2 reproj", "march r2 upsample", "march r2 oct 2")
NO_DETAIL = "march r2 reproj"          # what the octave rows are compared with
CONVERGE = 4                           # frames past r² before a reprojected image is read
NEAR = 0.6 / light.FRAMING            # parts 3, 4: the side view 0.6 x the old bench distance (the cloud fills more)
LOG: list[str] = []


def say(line: str = "") -> None:
    print(line, flush=True)
    LOG.append(line)


# -- a bench_cloud_light scene with the ray march added --------------------------------------------
class MarchScene:
    """bench_cloud_light's Scene (sprites + the ray march, both switchable), its march set to the
    real-time defaults | DEFAULT | a row's fields; :meth:`use` switches to one row's renderer."""

    def __init__(self, gpu, volume, extra=()):
        self.scene = light.Scene(gpu, volume, False, extra)
        self.app = self.scene.app
        self.plugin = self.scene.march
        self.pass_ = next(p for p in self.app.graph.passes if p.name == "cloud_raymarch")

    def use(self, fields):
        """``fields`` None: the default sprites; else the ray march with DEFAULT | fields."""
        s = self.scene
        if fields is None:
            s.mode({}, None)
            self.plugin.configure(enabled=False)
        else:
            s.renderer.configure(enabled=False)
            self.plugin.configure(enabled=True, **{**REAL_TIME, **DEFAULT, **fields})

    def converged(self, fields):
        """The image a still camera shows once the history holds every offset (r² + CONVERGE frames
        with reprojection; one frame otherwise)."""
        merged = {**DEFAULT, **(fields or {})}
        r = merged["resolution"] if fields is not None and merged["reprojection"] else 1
        if self.pass_.temporal is not None:
            self.pass_.temporal.reset()
        for _ in range(r * r + CONVERGE - 1 if r > 1 else 0):
            self.app.render()
        return self.app.read_linear()

    def close(self):
        self.app.close()


def change(image, base):
    """(image-sum change, rel. RMS difference over the base's cloud pixels) of ``image`` vs ``base``."""
    return light.errors(image, np.asarray(base, np.float64)[..., :3])


def error_vs_time(gpu, rows, volumes, view_names, samples):
    say(f"\n== 1. error vs time against the path tracer ({light.SIZE[0]}x{light.SIZE[1]}, tracer {samples} spp) ==")
    say("march rows: DEFAULT " + ", ".join(f"{k}={v}" for k, v in DEFAULT.items()) + " with the row's change; "
        f"reprojected rows read after r^2 + {CONVERGE} still frames")
    results = {}
    for vname in volumes:
        ms = MarchScene(gpu, light.VOLUMES[vname]())
        s = ms.scene
        say(f"\n{vname}: shape {s.density.shape}, cells {s.cell} m, sigma_t {s.sigma_t}/m")
        say(f"{'view':11s} {'row':18s} {'bias':>7s} {'rel RMSE':>9s} {'less noise':>10s} {'frame ms':>9s} {'x sprites':>9s}")
        images = []
        for view, (pos, target, elevation) in light.views(s.lo, s.hi).items():
            if view not in view_names:
                continue
            cam, sun = s.look(pos, target, elevation)
            ref, err, seconds = light.cached_reference(s, cam, sun, samples)
            noise_sum, noise_rmse = light.tracer_noise(ref, err)
            say(f"{view:11s} {'path tracer':18s} ±{100 * noise_sum:5.1f}% {100 * noise_rmse:8.1f}% "
                f"{'':10s} {1e3 * seconds:9.0f}  (its standard error; ms of the whole trace)")
            row_images, per_row = [ref], {}
            for label in rows:
                fields = ROWS[label]
                ms.use(fields)
                image = ms.converged(fields)
                per_row[label] = image
                frame_ms = s.frame_ms()
                row_images.append(image)
                if label.startswith("march r2 oct") and NO_DETAIL in per_row:
                    d_sum, d_rms = change(image, per_row[NO_DETAIL])
                    results[(vname, view, label)] = dict(bias=None, rmse=None, clean=None, ms=frame_ms,
                                                         change_sum=d_sum, change_rms=d_rms)
                    say(f"{'':11s} {label:18s} {100 * d_sum:+6.1f}% {100 * d_rms:8.1f}% {'':10s} {frame_ms:9.2f} "
                        f"{frame_ms / results[(vname, view, 'sprites 1/2')]['ms'] if (vname, view, 'sprites 1/2') in results else float('nan'):9.2f}"
                        f"  (change vs octaves 0, not error)")
                    continue
                bias, rmse = light.errors(image, ref)
                clean = light.less_noise(rmse, noise_rmse)
                results[(vname, view, label)] = dict(bias=bias, rmse=rmse, clean=clean, ms=frame_ms)
                base = results.get((vname, view, "sprites 1/2"))
                ratio = frame_ms / base["ms"] if base else float("nan")
                say(f"{'':11s} {label:18s} {100 * bias:+6.1f}% {100 * rmse:8.1f}% {100 * clean:9.1f}% "
                    f"{frame_ms:9.2f} {ratio:9.2f}")
            images.append(row_images)
        light.strip(images, OUT / f"bench_cloud_raymarch_images_{vname}.png")
        ms.close()
    plot_error(results, OUT / "bench_cloud_raymarch.png")
    return results


def plot_error(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cases = sorted({(v, w) for v, w, _ in results}, key=lambda c: list(dict.fromkeys(k[:2] for k in results)).index(c))
    import matplotlib.ticker
    cols = min(len(cases), 4)
    rows = -(-len(cases) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.8 * cols, 3.4 * rows), squeeze=False)
    for ax, (vname, view) in zip(axes.flat, cases):
        for (v, w, label), r in results.items():
            if (v, w) != (vname, view) or r["rmse"] is None:
                continue
            ax.scatter(r["ms"], 100 * r["clean"], label=label,
                       marker="o" if label.startswith("sprites") else ("s" if " r1" in label else "^"))
        ax.axhline(15, color="grey", lw=0.8, ls="--")
        ax.set_title(f"{vname}, {view}", fontsize=9)
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("frame ms (llvmpipe; ratios only)")
        ax.set_ylabel("rel. RMSE less tracer noise %")
    axes[0][0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


# -- 2. the sunset frame with each renderer ------------------------------------------------------
def sunset_with_both(app, settings):
    """The sunset demo with the ray march added (disabled) unless the demo already has one."""
    from atmos.demos import sunset
    sunset.build(app, settings)
    if not any(isinstance(p, RaymarchCloudsPlugin) for p in app.plugins):
        app.add_plugins(RaymarchCloudsPlugin(enabled=False))
    if not any(isinstance(p, CloudRenderPlugin) for p in app.plugins):
        app.add_plugins(CloudRenderPlugin(size_factor=4.0, enabled=False))


def sunset_rows(size=(1024, 768), rounds=2, frames=6) -> list[dict]:
    """Per renderer: median frame ms (glFinish, ``app.update(1/30)``), its cloud pass's ms from the
    render graph's timer queries, and the ratio to the sprites; renderers alternated ``rounds`` times
    in one App so both see the same sky and simulation."""
    from atmos.demo_registry import DemoSettings
    from atmos.graph.timing import RING
    from atmos.runner import build_app
    gpu = create_headless(size)
    try:
        app = build_app(sunset_with_both, DemoSettings(size=size, headless=True), gpu)
        try:
            sprites = next(p for p in app.plugins if isinstance(p, CloudRenderPlugin))
            march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
            ctx = gpu.ctx
            app.graph.timings_enabled = True
            wall = {"sprites": [], "march": []}
            passes = {"sprites": [], "march": []}
            names = {"sprites": "cloud_render", "march": "cloud_raymarch"}
            for _ in range(rounds):
                for label, on, off in (("sprites", sprites, march), ("march", march, sprites)):
                    off.configure(enabled=False)
                    on.configure(enabled=True)
                    app.run_frames(RING + 1, 1 / 30)     # the switch, compiles, the timer queries read again
                    for _ in range(frames):
                        ctx.finish()
                        start = time.perf_counter()
                        app.update(1 / 30)
                        ctx.finish()
                        wall[label].append((time.perf_counter() - start) * 1e3)
                        t = app.graph.timings.get(names[label])
                        if t:
                            passes[label].append(t[0])
            settings = {"sprites": "CloudRenderPlugin(size_factor=4)",
                        "march": ", ".join(f"{k}={getattr(march.settings, k)}" for k in DEFAULT)}
            rows = [{"renderer": label, "settings": settings[label], "frame_ms": statistics.median(wall[label]),
                     "pass": names[label],
                     "pass_gpu_ms": statistics.median(passes[label]) if passes[label] else float("nan")}
                    for label in ("sprites", "march")]
            for r in rows:
                r["x_sprites_frame"] = r["frame_ms"] / rows[0]["frame_ms"]
                r["x_sprites_pass"] = r["pass_gpu_ms"] / rows[0]["pass_gpu_ms"]
            return rows
        finally:
            app.close()
    finally:
        gpu.release()


def sunset_table(rounds, frames):
    size = (1024, 768)
    say(f"\n== 2. the sunset frame at {size[0]}x{size[1]}, each renderer ({rounds} rounds x {frames} frames, "
        f"alternated in one App) ==")
    rows = sunset_rows(size, rounds, frames)
    say(f"{'renderer':9s} {'frame ms':>9s} {'x sprites':>9s}   {'pass':14s} {'pass ms (timer)':>15s} {'x sprites':>9s}   settings")
    for r in rows:
        say(f"{r['renderer']:9s} {r['frame_ms']:9.1f} {r['x_sprites_frame']:9.2f}   {r['pass']:14s} "
            f"{r['pass_gpu_ms']:15.1f} {r['x_sprites_pass']:9.2f}   {r['settings']}")
    return rows


# -- 3. temporal stability --------------------------------------------------------------------------
STABILITY = {"r1": dict(resolution=1), "r2 reproj": dict(resolution=2), "r2 upsample": dict(resolution=2, reprojection=False),
             "r4 reproj": dict(resolution=4)}


def cloud_mask(*images) -> np.ndarray:
    """Pixels where any of ``images`` shows cloud (rgb sum above 1e-3 of the brightest)."""
    sums = [np.asarray(im, np.float64)[..., :3].sum(-1) for im in images]
    top = max(float(x.max()) for x in sums)
    return np.logical_or.reduce([x > 1e-3 * top for x in sums])


def cloud_scale(image) -> float:
    """The mean cloud radiance (rgb sum) of ``image``: the unit of the change and ghost tables."""
    rgb = np.asarray(image, np.float64)[..., :3].sum(-1)
    return float(rgb[cloud_mask(image)].mean())


def stability(gpu, frames, configs):
    say(f"\n== 3. temporal stability: still camera, frozen clouds (cumulus, side view at {NEAR:g} x its distance, {light.SIZE[0]}x{light.SIZE[1]}), "
        f"mean |frame - previous| of HDR rgb over the cloud pixels / mean cloud radiance, {frames} frames ==")
    ms = MarchScene(gpu, light.cumulus())
    s = ms.scene
    pos, target, elevation = light.views(s.lo, s.hi)["side"]
    s.look(target + (pos - target) * NEAR, target, elevation)
    curves = {}
    say(f"{'config':12s} {'settled mean':>12s} {'settled max':>11s} {'max/mean':>8s}   first frames")
    for label in configs:
        fields = STABILITY[label]
        ms.use(fields)
        ms.converged(fields)                 # compiles; resets the history
        ms.pass_.temporal.reset()
        images = [ms.app.read_linear()[..., :3].astype(np.float64) for _ in range(frames + 1)]
        scale = cloud_scale(images[-1])
        mask = cloud_mask(*images)
        d = np.array([np.abs(b - a).sum(-1)[mask].mean() / scale for a, b in zip(images, images[1:])])
        curves[label] = d
        r = fields.get("resolution", 1)
        settled = d[r * r + 1:] if len(d) > r * r + 2 else d
        say(f"{label:12s} {100 * settled.mean():11.3f}% {100 * settled.max():10.3f}% {settled.max() / max(settled.mean(), 1e-12):8.2f}   "
            + " ".join(f"{100 * v:.2f}" for v in d[:6]) + " %")
    ms.close()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for label, d in curves.items():
        ax.plot(np.arange(1, len(d) + 1), 100 * d, marker=".", label=label)
    ax.set_yscale("log")
    ax.set_xlabel("frame")
    ax.set_ylabel("mean |Δ| / mean cloud radiance, %")
    ax.set_title("frame-to-frame change, still camera, frozen clouds")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "bench_cloud_raymarch_stability.png", dpi=100)
    plt.close(fig)
    return curves


# -- 4. ghosting after a fast turn ----------------------------------------------------------------
TURNS = (20.0, 5.0)                    # degrees in one frame: past the default motion_limit, and within it


def ghosting(gpu, frames, clamps, limits):
    for turn in TURNS:
        ghost_after(gpu, turn, frames, clamps, limits)


def ghost_after(gpu, turn, frames, clamps, limits):
    say(f"\n== 4. ghosting after a {turn:g} deg turn in one frame (cumulus, side view at {NEAR:g} x its distance, r2 reprojection, jitter off): "
        f"error vs the converged image at the new view over the cloud pixels (either image), mean |Δ| and p99 / mean cloud radiance ==")
    from PIL import Image

    from atmos.render_core import tone_map
    ms = MarchScene(gpu, light.cumulus())
    s = ms.scene
    pos, target, elevation = light.views(s.lo, s.hi)["side"]
    cam, _ = s.look(target + (pos - target) * NEAR, target, elevation)
    yaw0 = cam.yaw
    fields = dict(resolution=2, jitter=False)
    ms.use(fields)
    cam.yaw = yaw0 + math.radians(turn)
    truth = ms.converged(fields)[..., :3].astype(np.float64)
    scale = cloud_scale(truth)
    w = light.SIZE[0]
    motion = math.radians(turn) / (2 * math.atan(math.tan(cam.fov_y / 2) * w / light.SIZE[1])) * w
    say(f"the turn moves the image by about {motion:.0f} px (of {w})")
    say(f"{'clamp':>5s} {'limit':>5s}   " + "  ".join(f"{'f' + str(k):>11s}" for k in (1, 2, 3, 4, 8)) + "   (mean% / p99%)")
    curves = {}
    exposure = 0.8 / max(float(np.percentile(truth[truth.sum(-1) > 0], 99)), 1e-6)
    for clamp in clamps:
        for limit in limits:
            ms.plugin.configure(history_clamp=clamp, motion_limit=limit)
            cam.yaw = yaw0
            ms.converged(fields)
            cam.yaw = yaw0 + math.radians(turn)
            seq = [ms.app.read_linear()[..., :3].astype(np.float64) for _ in range(frames)]
            e = [np.abs(im - truth).sum(-1)[cloud_mask(im, truth)] for im in seq]
            mean = np.array([x.mean() / scale for x in e])
            p99 = np.array([np.percentile(x, 99) / scale for x in e])
            curves[(clamp, limit)] = (mean, p99)
            say(f"{clamp:5.2f} {limit:5.0f}   " + "  ".join(
                f"{100 * mean[k - 1]:5.2f}/{100 * p99[k - 1]:5.1f}" if k <= frames else f"{'':11s}" for k in (1, 2, 3, 4, 8)))
            f1, f4 = seq[0], seq[min(3, frames - 1)]
            diffs = [np.repeat((4 * np.abs(im - truth).sum(-1, keepdims=True) / scale).clip(0, 1), 3, -1) for im in (f1, f4)]
            strip = np.concatenate([tone_map(im, exposure) for im in (f1, f4, truth)] + diffs, 1).repeat(2, 0).repeat(2, 1)
            Image.fromarray((strip * 255).astype(np.uint8)).save(OUT / f"cloud_temporal_ghost_{turn:g}deg_{clamp:g}_{limit:g}.png")
    ms.close()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for (clamp, limit), (mean, p99) in curves.items():
        x = np.arange(1, len(mean) + 1)
        axes[0].plot(x, 100 * mean, marker=".", label=f"clamp {clamp:g}, limit {limit:g}")
        axes[1].plot(x, 100 * p99, marker=".")
    for ax, what in zip(axes, ("mean |Δ|", "p99 |Δ|")):
        ax.set_xlabel("frame after the turn")
        ax.set_ylabel(f"{what} / mean cloud radiance, %")
        ax.set_yscale("symlog", linthresh=0.1)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / f"bench_cloud_raymarch_ghost_{turn:g}deg.png", dpi=100)
    plt.close(fig)
    return curves


# -- 5. ghosting after scene motion under a still camera -----------------------------------------
EVENT_ROWS = {"r2 reproj": dict(resolution=2), "r4 reproj": dict(resolution=4),
              "r2 upsample": dict(resolution=2, reprojection=False), "r4 upsample": dict(resolution=4, reprojection=False)}
EVENT_COLUMNS = (1, 2, 3, 4, 8, 12)


class Drift:
    """The whole static volume drifts sideways (+x) ``px`` image pixels per frame (the VolumeOrigin
    moves by fractional cells), camera still: wind carrying the clouds."""

    def __init__(self, px):
        self.px, self.fields = px, {}

    def start(self, ms, cam, target):
        from atmos.plugins.clouds.weather import VolumeOrigin
        self.origin = ms.app.resource(VolumeOrigin)
        self.x0 = self.origin.x
        focal = 0.5 * light.SIZE[1] / math.tan(cam.fov_y / 2)
        self.cells = self.px * float(np.linalg.norm(cam.position - target)) / focal / ms.scene.cell[0]
        return f"{self.cells * ms.scene.cell[0]:.2f} m/frame, {30 * self.cells * ms.scene.cell[0]:.0f} m/s at 30 frames/s"

    def at(self, ms, k):
        self.origin.x = self.x0 + k * self.cells

    def stop(self, ms):
        self.origin.x = self.x0


class DetailWind:
    """Only the detail noise moves: ``detail_octaves`` 3 scrolling with ``wind`` m/s at 30 frames/s
    (the frame clock advanced by hand), the smooth density still."""

    def __init__(self, speed):
        self.speed, self.fields = speed, dict(detail_octaves=3, wind=(speed, 0.0, 0.0))

    def start(self, ms, cam, target):
        self.t0 = ms.app.clock.frame_time
        return f"{self.speed / 30:.2f} m/frame of noise scroll"

    def at(self, ms, k):
        ms.app.clock.frame_time = self.t0 + k / 30

    def stop(self, ms):
        ms.app.clock.frame_time = self.t0


class Crossing:
    """A box (the cloud's height, a fifth of the view wide) at a third of the way to the cloud crosses
    in front of it sideways ``px`` pixels per frame, starting just left of the cloud's middle."""

    occluder = True      # the error is taken over the cloud's pixels without the box (the box's own are exact)

    def __init__(self, px):
        self.px, self.fields = px, {}

    def start(self, ms, cam, target):
        from atmos import Transform
        from atmos.plugins.mesh import MeshInstance, box
        self.mesh = next(p for p in ms.app.plugins if type(p).__name__ == "MeshPlugin")
        d = float(np.linalg.norm(cam.position - target)) / 3
        focal = 0.5 * light.SIZE[1] / math.tan(cam.fov_y / 2)
        right = cam.basis()[:, 0]
        width = 0.2 * light.SIZE[0] * d / focal
        self.step = right * self.px * d / focal
        self.p0 = cam.position + (target - cam.position) / 3 - right * width
        self.entity = ms.app.world.create_entity(Transform(self.p0.copy()),
                                                 MeshInstance(box((width, 0.5 * width, width)), (0.5, 0.45, 0.4)))
        self.transform = ms.app.world.component_for_entity(self.entity, Transform)
        self.at(ms, 0)
        return f"{width:.0f} m box at {d:.0f} m"

    def at(self, ms, k):
        self.transform.teleport(self.p0 + k * self.step)
        self.mesh.collect(ms.app)

    def stop(self, ms):
        ms.app.world.delete_entity(self.entity, immediate=True)
        self.mesh.collect(ms.app)


EVENTS = {"drift_0.5px": Drift(0.5), "drift_3px": Drift(3.0), "detail_wind": DetailWind(15.0),
          "crossing_4px": Crossing(4.0)}


def events(gpu, frames, cases):
    """Per case and row: converged with everything still, then the scene moves each frame; error per
    frame vs the resolution-1 march of that frame (jitter off), mean |Δ| and p99 over the cloud's
    pixels / mean cloud radiance; frames 1, 4 and the last of each case's r2 row in
    out/cloud_temporal_ghost_<case>_<row>.png (then |Δ| ×4)."""
    from PIL import Image

    from atmos.plugins.mesh import MeshPlugin
    from atmos.render_core import tone_map
    say(f"\n== 5. ghosting after scene motion, still camera (cumulus, side view at {NEAR:g} x its distance, jitter off): "
        f"error per frame vs the resolution-1 march of the same frame over the cloud pixels, mean |Δ| / p99 in % of the mean cloud radiance ==")
    ms = MarchScene(gpu, light.cumulus(), extra=(MeshPlugin(),))
    s = ms.scene
    pos, target, elevation = light.views(s.lo, s.hi)["side"]
    cam, _ = s.look(target + (pos - target) * NEAR, target, elevation)
    cols = [k for k in EVENT_COLUMNS if k <= frames]
    say(f"{'case':13s} {'row':12s} " + "  ".join(f"{'f' + str(k):>11s}" for k in cols) + f"  {'all frames':>11s}")
    results = {}
    for case in cases:
        ev = EVENTS[case]
        ms.use(dict(resolution=1, jitter=False, **ev.fields))
        clean = cloud_mask(ms.app.read_linear())
        what = ev.start(ms, cam, target)
        truths = []
        for k in range(frames + 1):
            ev.at(ms, k)
            truths.append(ms.app.read_linear()[..., :3].astype(np.float64))
        ev.at(ms, 0)
        scale = cloud_scale(truths[0])
        exposure = 0.8 / max(float(np.percentile(truths[0][truths[0].sum(-1) > 0], 99)), 1e-6)
        for label, row in EVENT_ROWS.items():
            fields = dict(jitter=False, **ev.fields, **row)
            ms.use(fields)
            ev.at(ms, 0)
            ms.converged(fields)
            seq = []
            for k in range(1, frames + 1):
                ev.at(ms, k)
                seq.append(ms.app.read_linear()[..., :3].astype(np.float64))
            e = [np.abs(im - t).sum(-1)[clean if getattr(ev, "occluder", False) else cloud_mask(im, t)]
                 for im, t in zip(seq, truths[1:])]
            mean = np.array([x.mean() / scale for x in e])
            p99 = np.array([np.percentile(x, 99) / scale for x in e])
            results[(case, label)] = (mean, p99)
            say(f"{case:13s} {label:12s} " + "  ".join(f"{100 * mean[k - 1]:5.2f}/{100 * p99[k - 1]:5.1f}" for k in cols)
                + f"  {100 * mean.mean():5.2f}/{100 * p99.mean():5.1f}")
            picks = sorted({0, min(3, frames - 1), frames - 1})
            diffs = [np.repeat((4 * np.abs(seq[i] - truths[i + 1]).sum(-1, keepdims=True) / scale).clip(0, 1), 3, -1) for i in picks]
            strip = np.concatenate([np.concatenate([tone_map(seq[i], exposure) for i in picks], 1),
                                    np.concatenate([tone_map(truths[i + 1], exposure) for i in picks], 1),
                                    np.concatenate(diffs, 1)], 0).repeat(2, 0).repeat(2, 1)
            Image.fromarray((strip * 255).astype(np.uint8)).save(OUT / f"cloud_temporal_ghost_{case}_{label.replace(' ', '_')}.png")
        ev.at(ms, 0)
        say(f"{'':13s} ({what}; frames {[k + 1 for k in picks]}: image, truth, |Δ| ×4)")
        ev.stop(ms)
    ms.close()
    return results


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer rows, views, frames and tracer samples")
    ap.add_argument("--size", default="192x128", help="image size WxH of parts 1, 3, 4")
    ap.add_argument("--samples", type=int, default=None, help="path-tracer samples per pixel (128; --quick 32)")
    ap.add_argument("--only", nargs="+", choices=PARTS, default=list(PARTS), metavar="PART",
                    help=f"run only these parts ({', '.join(PARTS)})")
    args = ap.parse_args(argv)
    light.SIZE = tuple(int(v) for v in args.size.lower().split("x"))
    q = args.quick
    samples = args.samples or (32 if q else 128)
    OUT.mkdir(exist_ok=True)
    started = time.perf_counter()
    gpu = create_headless(light.SIZE)
    say(f"bench_cloud_raymarch: {gpu.info().get('GL_RENDERER')}{' (--quick)' if q else ''}")
    try:
        if "error" in args.only:
            error_vs_time(gpu, QUICK_ROWS if q else list(ROWS), ["ellipsoid"] if q else list(light.VOLUMES),
                          ("side", "toward sun") if q else ("side", "below", "toward sun", "grazing"), samples)
        if "stability" in args.only:
            stability(gpu, 12 if q else 32, ("r1", "r2 reproj") if q else list(STABILITY))
        if "ghost" in args.only:
            ghosting(gpu, 6 if q else 12, (0.0, 1.0) if q else (0.0, 0.5, 1.0), (16.0, 64.0) if q else (4.0, 16.0, 64.0))
        if "events" in args.only:
            events(gpu, 6 if q else 12, ("drift_3px", "crossing_4px") if q else list(EVENTS))
    finally:
        gpu.release()
    if "sunset" in args.only:
        sunset_table(1 if q else 2, 3 if q else 6)
    say(f"\ntotal {time.perf_counter() - started:.0f} s")
    (OUT / f"bench_cloud_raymarch_{light.SIZE[0]}x{light.SIZE[1]}.txt").write_text("\n".join(LOG) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
