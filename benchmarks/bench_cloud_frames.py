"""Frame time of a cloud scene with the cloud chain sliced over frames, run whole, or paused.

A plain script (``python3 benchmarks/bench_cloud_frames.py [--shape 256 32 256] [--frames 60]``):
the whole cloud chain (region → automaton → smoothing → density maps → shading) feeds a top view
of the cloud field. Modes: ``paused`` (the scene without simulation work), ``sliced`` (one slice
per frame: the frame time should stay near paused plus the largest slice), ``naive`` (a whole
step every frame). Each frame ends with ``ctx.finish()``; prints median, p99 and max ms.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from atmos.app import App
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.plugins.clouds import CloudSettings, CloudsPlugin, CloudSimulation
from atmos.plugins.clouds.simulation.top_view import CloudTopViewPlugin
from atmos.plugins.clouds.weather import WeatherSettings


def scene(gpu, shape, mode: str) -> App:
    nx, ny, nz = shape
    params = WeatherSettings(volume_shape=shape, cloud_density=int(nx * nz / 400), density_adaption=8,
                           cloud_size=nx / 20, cloud_size_variance=nx / 60, region_margin=nx / 16,
                           lifetime=300.0, lifetime_variance=50.0, hum_scale=0.2, act_scale=0.01, ext_scale=0.1)
    settings = CloudSettings(smoothing_slices=max(1, nz // 8), group_size=(32, 32))
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudsPlugin(settings, weather=params, warmup_steps=20),
                               CloudTopViewPlugin())
    app.frames.mode = "naive" if mode == "naive" else "sliced"
    if mode == "paused":
        app.frames.remove(app.resource(CloudSimulation).job)
    app.startup()
    return app


def measure(gpu, shape, mode: str, frames: int) -> np.ndarray:
    app = scene(gpu, shape, mode)
    times = []
    for i in range(frames + 3):
        gpu.ctx.finish()
        start = time.perf_counter()
        app.update(1 / 30)
        gpu.ctx.finish()
        if i >= 3:
            times.append((time.perf_counter() - start) * 1e3)
    sim = app.resource(CloudSimulation)
    slices = sim.job.slices_in_step
    app.close()
    return np.array(times), slices


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shape", type=int, nargs=3, default=(256, 32, 256))
    parser.add_argument("--frames", type=int, default=60)
    args = parser.parse_args()
    shape = tuple(args.shape)
    gpu = create_headless((640, 480))
    print(f"cloud scene frame time, {shape[0]}x{shape[1]}x{shape[2]} cells, 640x480, "
          f"{gpu.ctx.info['GL_RENDERER']}, {args.frames} frames per mode, ctx.finish() per frame")
    print(f"{'mode':28s} {'median ms':>10s} {'p99 ms':>10s} {'max ms':>10s}")
    rows = {}
    for mode in ("paused", "sliced", "naive"):
        times, slices = measure(gpu, shape, mode, args.frames)
        rows[mode] = times
        label = {"paused": "paused (no simulation)", "sliced": f"sliced (1 of {slices} slices/frame)",
                 "naive": "naive (whole step/frame)"}[mode]
        print(f"{label:28s} {np.median(times):10.2f} {np.percentile(times, 99):10.2f} {times.max():10.2f}")
    print(f"sliced / paused median: {np.median(rows['sliced']) / np.median(rows['paused']):.2f}x; "
          f"naive / sliced max: {rows['naive'].max() / rows['sliced'].max():.1f}x")
    gpu.release()


if __name__ == "__main__":
    main()
