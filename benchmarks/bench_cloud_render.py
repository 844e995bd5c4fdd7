"""Point-sprite cloud rendering: frame time by cloud cover and culling (thesis Tables 8.2–8.4), and
the sprite image's error against a ray-marched reference versus frame time.

A plain script (``python benchmarks/bench_cloud_render.py [--quick]``):

1. 256×32×256 cells at 1024×768 (``--quick``: 128×16×128 at 512×384, labelled), low / medium /
   high cover (cover measured with ``sim.cover()``), no culling / frustum culling / frustum +
   empty-space skipping; render-graph time only (no simulation slices), ``ctx.finish()`` per
   frame, median of 20 frames; printed beside the thesis's fps and speed-ups.
2. 96×16×96 cells at 480×360: RMSE (display values 0..1) of the sprite image against a
   1024-sample ray march of the same volume, per group size × sprite size factor × culling,
   against frame time; a table and ``out/bench_cloud_render.png``.

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
from atmos.plugins.cloud_render import CloudReferencePlugin, CloudRenderPlugin
from atmos.plugins.cloud_render.example import example_weather
from atmos.plugins.clouds import CloudSettings, CloudSimulation, CloudsPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin

OUT = Path(__file__).resolve().parents[1] / "out" / "bench_cloud_render.png"
THESIS = {"low": (33, 95, 118), "medium": (25, 51, 55), "high": (11, 21, 33)}   # fps: none, VFD, VFD+ESS
THESIS_SPEEDUP = {"low": 3.6, "medium": 2.2, "high": 3.0}
COVERS = {"low": 50, "medium": 150, "high": 400}      # ellipsoids (cloud_density) for 256 wide; scaled by area
MODES = {"none": (False, False), "frustum": (True, False), "frustum+ESS": (True, True)}
BASE = 600.0


def make_app(gpu, shape, cloud_density, group, cell, size_factor=3.0, reference_steps=0, warmup=16):
    app = App(gpu)
    app.insert_resource(Sun.from_angles(30.0, 40.0))
    settings = CloudSettings(smoothing_slices=4, group_size=group, cell_size=cell)
    weather = example_weather(shape, cloud_density, density_adaption=max(4, cloud_density // 10))
    renderer = CloudRenderPlugin(base_altitude=BASE, size_factor=size_factor)
    plugins = [DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(),
               CloudsPlugin(weather, settings, seed=1, warmup_steps=warmup), renderer]
    reference = CloudReferencePlugin(renderer, steps=reference_steps, enabled=False) if reference_steps else None
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
        app.graph.execute(app=app)
        ctx.finish()
        times.append(time.perf_counter() - start)
    return float(np.median(times[2:]) * 1e3)


def culling_table(quick: bool) -> None:
    shape, size = ((128, 16, 128), (512, 384)) if quick else ((256, 32, 256), (1024, 768))
    cell = (20.0, 10.0, 20.0)
    gpu = create_headless(size)
    print(f"\n1) frame time, {shape[0]}x{shape[1]}x{shape[2]} cells, {size[0]}x{size[1]}, group 32x32, "
          f"{gpu.ctx.info['GL_RENDERER']}" + ("  [--quick: SMALLER than the thesis's setup]" if quick else ""))
    print(f"{'cover':>8} {'actual':>7} | {'mode':>12} {'ms':>8} {'fps':>7} {'segments':>9} {'speed-up':>8} |"
          f" {'thesis fps':>10} {'thesis x':>8}")
    area = shape[0] * shape[2] / 256 ** 2
    for level, density in COVERS.items():
        app, renderer, _ = make_app(gpu, shape, max(1, round(density * area)), (32, 32), cell)
        place_camera(app, shape, cell)
        cover = app.resource(CloudSimulation).cover()
        base_ms = None
        for i, (mode, (vfd, ess)) in enumerate(MODES.items()):
            renderer.frustum_culling, renderer.empty_space_skipping = vfd, ess
            ms = render_ms(app, 8 if quick else 20)
            base_ms = base_ms or ms
            thesis = THESIS[level][i]
            speed = f"x{base_ms / ms:.1f}"
            ts = f"x{THESIS[level][i] / THESIS[level][0]:.1f}"
            print(f"{level:>8} {cover:>7.0%} | {mode:>12} {ms:>8.1f} {1e3 / ms:>7.1f} "
                  f"{renderer.stats.segments_drawn:>9} {speed:>8} | {thesis:>10} {ts:>8}")
        print(f"{'':>8} {'':>7} | goal: our frustum+ESS speed-up >= thesis x{THESIS_SPEEDUP[level]}")
        app.close()
    gpu.release()


def error_table():
    shape, size, cell = (96, 16, 96), (480, 360), (20.0, 15.0, 20.0)
    gpu = create_headless(size)
    print(f"\n2) error vs run time, {shape[0]}x{shape[1]}x{shape[2]} cells, {size[0]}x{size[1]}, "
          "RMSE of display values (0..1) against a 1024-sample ray march")
    print(f"{'group':>6} {'size':>5} {'culling':>8} {'ms':>8} {'RMSE':>8} {'segments':>9}")
    rows = []
    for group in (8, 16, 32):
        app, renderer, reference = make_app(gpu, shape, 80, (group, group), cell, reference_steps=1024, warmup=20)
        cam = app.resource(Camera)
        cam.position = np.array([200.0, BASE - 150.0, 1700.0])
        cam.look_at((960.0, BASE + 120.0, 700.0))
        cam.far = 8000.0
        renderer.enabled, reference.enabled = False, True
        app.graph.execute(app=app)
        ref = gpu.read_pixels() / 255.0
        renderer.enabled, reference.enabled = True, False
        for size_factor in (1.5, 2.0, 3.0, 4.0):
            for culling in (False, True):
                renderer.size_factor = size_factor
                renderer.frustum_culling = renderer.empty_space_skipping = culling
                ms = render_ms(app, 6)
                rmse = float(np.sqrt(((gpu.read_pixels() / 255.0 - ref) ** 2).mean()))
                rows.append((group, size_factor, culling, ms, rmse))
                print(f"{group:>6} {size_factor:>5} {'on' if culling else 'off':>8} {ms:>8.1f} {rmse:>8.4f} "
                      f"{renderer.stats.segments_drawn:>9}")
        app.close()
    gpu.release()
    return rows


def plot(rows) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for group, marker in ((8, "o"), (16, "s"), (32, "^")):
        for culling, fill in ((False, "none"), (True, "full")):
            sel = [r for r in rows if r[0] == group and r[2] == culling]
            ax.plot([r[3] for r in sel], [r[4] for r in sel], marker=marker, fillstyle=fill, linestyle="-",
                    label=f"group {group}, culling {'on' if culling else 'off'}")
            for r in sel:
                ax.annotate(f"{r[1]:g}", (r[3], r[4]), fontsize=7, xytext=(3, 3), textcoords="offset points")
    ax.set_xlabel("frame time (ms, render graph)")
    ax.set_ylabel("RMSE vs ray-marched reference")
    ax.set_title("point-sprite clouds: error vs run time (labels: sprite size factor)")
    ax.legend(fontsize=7)
    OUT.parent.mkdir(exist_ok=True)
    fig.tight_layout()
    fig.savefig(OUT, dpi=120)
    print(f"wrote {OUT}")


def main() -> None:
    quick = "--quick" in sys.argv
    start = time.perf_counter()
    culling_table(quick)
    plot(error_table())
    print(f"total {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
