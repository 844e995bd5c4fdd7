"""Point-sprite cloud rendering: frame time by cloud cover and culling (thesis Tables 8.2–8.4), and
the sprite image's error against a ray-marched reference versus frame time.

A plain script (``python benchmarks/bench_cloud_render.py [--quick | --work]``; ``--work`` alone: the
sprites' per-frame work in sunset and flight at 1920×1080, points against the compute splat, as counts):

1. 256×32×256 cells at 1024×768 (``--quick``: 128×16×128 at 512×384, labelled), low / medium /
   high cover (cover measured with ``sim.cover()``): the thesis's rows (no culling, frustum culling
   (VFD), VFD + empty-space skipping (ESS), full resolution) and ours (the sprites off screen at
   1/2 resolution, plus levels of detail); render-graph time of the whole frame (sky, ground,
   clouds; no simulation slices), ``ctx.finish()`` per frame, median of 20 frames; printed beside
   the thesis's fps and speed-ups. "ms" draws blended points, "splat ms" the same sprites splatted in
   compute (``splat="compute"``), side by side.
2. 96×16×96 cells at 480×360: RMSE (display values 0..1) of the sprite image against the
   reference ray march of the same volume (``RaymarchCloudsPlugin.reference()``) against frame time, per group size × sprite size
   factor × culling, and per downsample × level of detail; a table and ``out/bench_cloud_render.png``.
3. The same volume seen from the side, from below and edge-on (the defaults: group 16, size 3,
   culled, 1/2 resolution): RMSE per view; the images beside their references in ``out/``.

On llvmpipe (no GPU) only the ratios measured side by side in this run mean anything.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.lighting import Sun
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.weather.example import example_weather
from atmos.plugins.clouds import CloudSettings, CloudSimulation, CloudsPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin

OUT = Path(__file__).resolve().parents[1] / "out" / "bench_cloud_render.png"
THESIS = {"low": (33, 95, 118), "medium": (25, 51, 55), "high": (11, 21, 33)}   # fps: none, VFD, VFD+ESS
THESIS_SPEEDUP = {"low": 3.6, "medium": 2.2, "high": 3.0}
COVERS = {"low": 50, "medium": 150, "high": 400}      # ellipsoids (cloud_density) for 256 wide; scaled by area
BASE = 600.0


def make_app(gpu, shape, cloud_density, group, cell, size_factor=3.0, reference=False, warmup=16):
    app = App(gpu)
    app.insert_resource(Sun.from_angles(30.0, 40.0))
    settings = CloudSettings(smoothing_slices=4, group_size=group, cell_size=cell, base_altitude=BASE)
    weather = example_weather(shape, cloud_density, density_adaption=max(4, cloud_density // 10))
    renderer = CloudRenderPlugin(size_factor=size_factor)
    plugins = [DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(),
               CloudsPlugin(settings, weather=weather, seed=1, warmup_steps=warmup), renderer]
    reference = RaymarchCloudsPlugin.reference(enabled=False) if reference else None
    app.add_plugins(*plugins, *([reference] if reference else []))
    app.startup()
    app.update(1 / 60)
    return app, renderer, reference


def place_camera(app, shape, cell):
    """Below the layer near its middle, looking slightly up over it (like the thesis's ground views)."""
    cam = app.resource(Camera)
    w, d = shape[0] * cell[0], shape[2] * cell[2]
    cam.position = np.array([0.5 * w, BASE - 250.0, 0.5 * d])
    cam.yaw, cam.pitch, cam.far = 0.7, 0.3, 4.0 * max(w, d)


def render_ms(app, frames=20) -> float:
    ctx = app.gpu.ctx
    times = []
    for _ in range(frames + 2):
        ctx.finish()
        start = time.perf_counter()
        app.render()
        ctx.finish()
        times.append(time.perf_counter() - start)
    return float(np.median(times[2:]) * 1e3)


CONFIGS = {   # label: (frustum, ESS, downsample, lod_pixels)
    "none": (False, False, 1, None),
    "VFD": (True, False, 1, None),
    "VFD+ESS": (True, True, 1, None),
    "1/2 res, none": (False, False, 2, None),
    "1/2 res, VFD+ESS": (True, True, 2, None),
    "1/2 res, VFD+ESS+LOD 4px": (True, True, 2, 4.0),
    "1/2 res, VFD+ESS+LOD 8px": (True, True, 2, 8.0),
}


def configure(renderer, frustum, ess, downsample, lod_pixels) -> None:
    renderer.configure(frustum_culling=frustum, empty_space_skipping=ess, downsample=downsample,
                       lod_pixels=lod_pixels)


def culling_rows(gpu, shape, frames: int = 20, cell=(20.0, 10.0, 20.0)) -> list[dict]:
    """Frame time per cover (``COVERS``, scaled by the volume's area) and config (``CONFIGS``) at the
    size of ``gpu``: one dict per row, with the thesis's fps where it has one (the first three)."""
    rows = []
    area = shape[0] * shape[2] / 256 ** 2
    for level, density in COVERS.items():
        app, renderer, _ = make_app(gpu, shape, max(1, round(density * area)), (32, 32), cell)
        place_camera(app, shape, cell)
        cover = app.resource(CloudSimulation).cover()
        none_ms = {}
        for i, (label, config) in enumerate(CONFIGS.items()):
            configure(renderer, *config)
            renderer.configure(splat="compute")
            splat_ms = render_ms(app, frames)
            renderer.configure(splat="points")
            ms = render_ms(app, frames)
            none_ms.setdefault(config[2], ms)                # the first row at each resolution is "none"
            rows.append({"cover": level, "actual_cover": cover, "config": label, "ms": ms, "fps": 1e3 / ms,
                         "splat_ms": splat_ms, "x_splat": ms / splat_ms,
                         "sprites": renderer.stats.sprites, "x_none": none_ms[1] / ms,
                         "x_same_res_none": none_ms[config[2]] / ms,
                         "thesis_fps": THESIS[level][i] if i < 3 else None,
                         "thesis_x": THESIS[level][i] / THESIS[level][0] if i < 3 else None})
        app.close()
    return rows


def culling_table(quick: bool) -> None:
    shape, size = ((128, 16, 128), (512, 384)) if quick else ((256, 32, 256), (1024, 768))
    gpu = create_headless(size)
    print(f"\n1) frame time, {shape[0]}x{shape[1]}x{shape[2]} cells, {size[0]}x{size[1]}, group 32x32, "
          f"{gpu.ctx.info['GL_RENDERER']}" + ("  [--quick: SMALLER than the thesis's setup]" if quick else ""))
    print("   thesis rows: full resolution, no LOD (Tables 8.2-8.4); ours add the off-screen 1/2-res target "
          "and levels of detail")
    print(f"{'cover':>6} {'actual':>6} | {'config':>25} {'ms':>7} {'fps':>6} {'splat ms':>8} {'x splat':>7} "
          f"{'sprites':>8} {'x none':>6} {'x same-res none':>15} | {'thesis fps':>10} {'thesis x':>8}")
    rows = culling_rows(gpu, shape, 8 if quick else 20)
    for r in rows:
        thesis = f"{r['thesis_fps']:>10} {r['thesis_x']:>7.1f}x" if r["thesis_fps"] else ""
        print(f"{r['cover']:>6} {r['actual_cover']:>6.0%} | {r['config']:>25} {r['ms']:>7.1f} {r['fps']:>6.1f} "
              f"{r['splat_ms']:>8.1f} {r['x_splat']:>6.2f}x {r['sprites']:>8} {r['x_none']:>5.1f}x {r['x_same_res_none']:>14.1f}x | {thesis}")
        if r["config"] == list(CONFIGS)[-1]:
            print(f"{'':>6} {'':>6} | goal: culling speed-up >= thesis x{THESIS_SPEEDUP[r['cover']]}")
    gpu.release()


ERROR_SHAPE, ERROR_SIZE, ERROR_CELL = (96, 16, 96), (480, 360), (20.0, 15.0, 20.0)
VIEWS = {"side": ((200.0, BASE - 150.0, 1700.0), (960.0, BASE + 120.0, 700.0)),
         "below": ((900.0, BASE - 60.0, 900.0), (1400.0, BASE + 200.0, 1300.0)),
         "edge-on": ((-300.0, BASE + 100.0, 960.0), (960.0, BASE + 100.0, 960.0))}


def error_app(gpu, group):
    app, renderer, reference = make_app(gpu, ERROR_SHAPE, 80, (group, group), ERROR_CELL, reference=True, warmup=20)
    look_from(app, *VIEWS["side"])
    return app, renderer, reference


def look_from(app, position, target) -> None:
    cam = app.resource(Camera)
    cam.position = np.array(position)
    cam.look_at(target)
    cam.far = 8000.0


def reference_image(app, renderer, reference) -> np.ndarray:
    renderer.configure(enabled=False)
    reference.configure(enabled=True)
    app.render()
    renderer.configure(enabled=True)
    reference.configure(enabled=False)
    return app.gpu.read_pixels() / 255.0


def error_table():
    """Rows (group, size factor, culling, downsample, lod_pixels, ms, RMSE, sprites)."""
    shape, size = ERROR_SHAPE, ERROR_SIZE
    gpu = create_headless(size)
    print(f"\n2) error vs run time, {shape[0]}x{shape[1]}x{shape[2]} cells, {size[0]}x{size[1]}, "
          "RMSE of display values (0..1) against the reference ray march")
    print(f"{'group':>6} {'size':>5} {'culling':>8} {'downsample':>10} {'LOD px':>7} {'ms':>8} {'RMSE':>8} "
          f"{'sprites':>8}")
    sweeps = {8: [(f, c, 1, None) for f in (1.5, 2.0, 3.0, 4.0) for c in (False, True)],
              16: [(f, c, 1, None) for f in (1.5, 2.0, 3.0, 4.0) for c in (False, True)]
              + [(3.0, True, k, lod) for k in (1, 2, 4) for lod in (None, 2.0, 4.0, 8.0) if (k, lod) != (1, None)],
              32: [(f, c, 1, None) for f in (1.5, 2.0, 3.0, 4.0) for c in (False, True)]}
    rows = []
    for group, configs in sweeps.items():
        app, renderer, reference = error_app(gpu, group)
        ref = reference_image(app, renderer, reference)
        for size_factor, culling, downsample, lod in configs:
            renderer.configure(size_factor=size_factor)
            configure(renderer, culling, culling, downsample, lod)
            ms = render_ms(app, 6)
            rmse = float(np.sqrt(((gpu.read_pixels() / 255.0 - ref) ** 2).mean()))
            rows.append((group, size_factor, culling, downsample, lod, ms, rmse, renderer.stats.sprites))
            print(f"{group:>6} {size_factor:>5} {'on' if culling else 'off':>8} {downsample:>10} "
                  f"{lod or '-':>7} {ms:>8.1f} {rmse:>8.4f} {renderer.stats.sprites:>8}")
        app.close()
    gpu.release()
    return rows


def view_table() -> None:
    from PIL import Image
    gpu = create_headless(ERROR_SIZE)
    app, renderer, reference = error_app(gpu, 16)
    renderer.configure(size_factor=3.0)
    print("\n3) RMSE by view, group 16, size 3, culled, 1/2 resolution")
    for name, (position, target) in VIEWS.items():
        look_from(app, position, target)
        ref = reference_image(app, renderer, reference)
        app.render()
        img = gpu.read_pixels() / 255.0
        path = OUT.with_name(f"bench_cloud_render_{name}.png")
        Image.fromarray((np.concatenate([img, ref], 1) * 255).round().astype(np.uint8)).save(path)
        print(f"{name:>8}: RMSE {np.sqrt(((img - ref) ** 2).mean()):.4f}   (sprites | reference: {path.name})")
    app.close()
    gpu.release()


def plot(rows) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12, 4.5))
    full = [r for r in rows if r[3] == 1 and r[4] is None]
    for group, marker in ((8, "o"), (16, "s"), (32, "^")):
        for culling, fill in ((False, "none"), (True, "full")):
            sel = [r for r in full if r[0] == group and r[2] == culling]
            ax.plot([r[5] for r in sel], [r[6] for r in sel], marker=marker, fillstyle=fill, linestyle="-",
                    label=f"group {group}, culling {'on' if culling else 'off'}")
            for r in sel:
                ax.annotate(f"{r[1]:g}", (r[5], r[6]), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_title("full resolution (labels: sprite size factor)")
    for downsample, marker in ((1, "s"), (2, "D"), (4, "v")):
        sel = [r for r in rows if r[0] == 16 and r[1] == 3.0 and r[2] and r[3] == downsample]
        sel.sort(key=lambda r: r[4] or 0)
        bx.plot([r[5] for r in sel], [r[6] for r in sel], marker=marker, linestyle="-",
                label=f"downsample {downsample}")
        for r in sel:
            bx.annotate(f"LOD {r[4]:g}" if r[4] else "no LOD", (r[5], r[6]), fontsize=7, xytext=(3, 3),
                        textcoords="offset points")
    bx.set_title("group 16, size 3, culled: downsample x levels of detail")
    for a in (ax, bx):
        a.set_xlabel("frame time (ms, render graph)")
        a.set_ylabel("RMSE vs ray-marched reference")
        a.legend(fontsize=7)
    fig.suptitle("point-sprite clouds: error vs run time")
    OUT.parent.mkdir(exist_ok=True)
    fig.tight_layout()
    fig.savefig(OUT, dpi=120)
    print(f"wrote {OUT}")


def splat_work(demos=("sunset", "flight"), size=(1920, 1080), frames: int = 4) -> list[dict]:
    """Per-frame work of the sprites in the demos (``--clouds sprites``) at ``size``: the pixels their point
    squares cover (what blended points fill: the overdraw) against the sprite-pixel pairs the compute
    splat tests and shades front to back (``SpriteSplat.count``); counts, not times, so the same on any
    machine."""
    from atmos.demo_registry import DemoSettings
    from atmos.plugins.clouds.sprites.splat import SpriteSplat
    from atmos.runner import build_app
    rows = []
    SpriteSplat.count = True
    try:
        for demo in demos:
            gpu = create_headless(size)
            app = build_app(demo, DemoSettings(size=size, headless=True, clouds="sprites"), gpu)
            renderer = next(p for p in app.plugins if isinstance(p, CloudRenderPlugin))
            renderer.configure(splat="compute")
            app.run_frames(frames, 1 / 30)
            work = renderer.sprite_pass.splat.work()
            factor = renderer.settings.downsample
            pixels = -(-size[0] // factor) * -(-size[1] // factor)
            rows.append({"demo": demo, "pixels": pixels, **work, "overdraw": work["covered"] / pixels,
                         "x_covered": work["covered"] / max(work["shaded"], 1)})
            app.close()
            gpu.release()
    finally:
        SpriteSplat.count = False
    return rows


def work_table() -> None:
    print("\nsprite work per frame at 1920x1080 (off screen at 1/2): points fill every covered pixel, the "
          "splat shades front to back until opaque")
    print(f"{'demo':>8} {'pixels':>9} {'sprites':>9} {'covered':>11} {'overdraw':>8} {'tested':>11} {'shaded':>11} "
          f"{'covered/shaded':>14}")
    for r in splat_work():
        print(f"{r['demo']:>8} {r['pixels']:>9} {r['sprites']:>9} {r['covered']:>11} {r['overdraw']:>8.1f} "
              f"{r['tested']:>11} {r['shaded']:>11} {r['x_covered']:>13.1f}x")


def main() -> None:
    quick = "--quick" in sys.argv
    if "--work" in sys.argv:
        work_table()
        return
    start = time.perf_counter()
    culling_table(quick)
    plot(error_table())
    view_table()
    print(f"total {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
