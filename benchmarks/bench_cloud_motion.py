"""How evenly the clouds move: the frame-to-frame image change over ~60 frames (issue 12, motion).

A plain script (``python3 benchmarks/bench_cloud_motion.py [--frames N] [--size WxH]``): a cloud
scene (the demos' slices per frame, 3) seen by a still camera, once with a still volume and once
with the volume's origin moving a cell every few frames (what ``follow_camera`` does in
``flight``). Per frame it records the mean absolute change of the picture (8-bit units) and the
interpolation factor t, prints their statistics (a dip is a frame whose change is far below the
median; a spike one far above) and plots both to ``out/bench_cloud_motion.png``.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.lighting import Sun
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.weather.example import example_weather
from atmos.plugins.clouds import CloudSettings, CloudSimulation, CloudsPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.clouds.weather import VolumeOrigin

ROOT = Path(__file__).resolve().parents[1]
SHAPE, CELL, BASE = (64, 12, 64), (20.0, 15.0, 20.0), 300.0


def run(gpu, frames: int, cells_per_frame: float) -> tuple[np.ndarray, np.ndarray]:
    """(change per frame, shown time step + t per frame)."""
    app = App(gpu).insert_resource(Sun.from_angles(30.0, 40.0)).insert_resource(VolumeOrigin())
    settings = CloudSettings(smoothing_slices=5, group_size=(16, 16), cell_size=CELL, base_altitude=BASE)
    app.add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(),
                    CloudsPlugin(settings, weather=example_weather(SHAPE, 80, wind=(0.3, 0.0, 0.1)), seed=4,
                                 warmup_steps=20), CloudRenderPlugin())
    app.frames.slices_per_frame = 3
    app.startup()
    cam = app.resource(Camera)
    cam.position, cam.far = np.array([700.0, 60.0, 300.0]), 6000.0
    cam.look_at((640.0, 400.0, 640.0))
    origin, sim = app.resource(VolumeOrigin), app.resource(CloudSimulation)
    images, shown = [], []
    for k in range(frames + 1):
        origin.x = float(np.floor(k * cells_per_frame))
        app.update(1 / 60)
        images.append(gpu.read_pixels().astype(np.float64))
        shown.append(sim.job.step + sim.job.progress)
    print(f"  {sim.job.slices_in_step} slices per step")
    app.close()
    return np.abs(np.diff(np.stack(images), axis=0)).mean(axis=(1, 2, 3)), np.array(shown[1:])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--size", default="320x180")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    gpu = create_headless(size)
    print(f"renderer: {gpu.ctx.info['GL_RENDERER']}, {size[0]}x{size[1]}, {args.frames} frames, 3 slices per frame")
    rows = {}
    for label, speed in (("still volume", 0.0), ("moving volume (1 cell / 4 frames)", 0.25)):
        change, shown = run(gpu, args.frames, speed)
        dt = np.diff(shown)
        med = float(np.median(change))
        rows[label] = (change, shown)
        print(f"{label:36s} change median {med:.3f}  min/median {change.min() / med:.2f}  "
              f"max/median {change.max() / med:.2f}  | t increment mean {dt.mean():.4f} "
              f"min {dt.min():.4f} max {dt.max():.4f}")
    gpu.release()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for label, (change, shown) in rows.items():
        top.plot(change, label=label)
        bottom.plot(np.diff(shown, prepend=shown[0]), label=label)
    top.set_ylabel("mean |frame − previous| (8-bit)")
    bottom.set_ylabel("shown step + t, increment")
    bottom.set_xlabel("frame")
    top.legend()
    top.set_title("cloud motion: frame-to-frame change (no periodic dips or spikes)")
    (ROOT / "out").mkdir(exist_ok=True)
    fig.savefig(ROOT / "out" / "bench_cloud_motion.png", dpi=100)
    print(f"plot: {ROOT / 'out' / 'bench_cloud_motion.png'}")


if __name__ == "__main__":
    main()
