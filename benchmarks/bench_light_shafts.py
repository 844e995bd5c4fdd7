"""Light shafts: frame cost of the marched shafts vs the screen-space ones in the sunset demo (one run,
this machine), and the march's error vs its step count against a 256-step march (float64 reference,
two cloud slabs with a gap, looking along it). Prints numbers; `.venv/bin/python benchmarks/bench_light_shafts.py`."""
from __future__ import annotations

import math

import numpy as np

from atmos import create_headless
from atmos.camera import Camera, view_basis
from atmos.demo_registry import DemoSettings
from atmos.plugins.clouds.layout import CloudLayout
from atmos.plugins.cloud_shadows.reference import sun_optical_depth
from atmos.plugins.light_shafts import LightShaftSettings, LightShaftsPass, reference
from atmos.runner import build_app

SIZE = (640, 360)


def pass_ms(mode: str, frames: int = 30) -> float:
    gpu = create_headless(SIZE)
    app = build_app("sunset", DemoSettings(size=SIZE, headless=True), gpu)
    next(p for p in app.graph.passes if isinstance(p, LightShaftsPass)).plugin.configure(mode=mode)
    app.run_frames(5, 1 / 30)
    total = 0.0
    for _ in range(frames):
        app.run_frames(1, 1 / 30)
        total += app.graph.timings["light_shafts"][0]
    app.close()
    gpu.release()
    return total / frames


def step_errors(steps=(4, 8, 16, 24, 48, 128)) -> list[tuple[int, float]]:
    shape, cell = (32, 4, 32), (20.0, 25.0, 20.0)
    volume = np.zeros(shape)
    volume[2:14] = volume[18:30] = 1.0
    sums = volume.sum(axis=1)
    layout = CloudLayout(shape, cell, (0.0, 0.0), 200.0, (8, 8), 0.0)
    sun = np.array([0.0, 1.0, 0.25]) / math.hypot(1.0, 0.25)
    tau = lambda p: sun_optical_depth(p, sums, sums, 0.0, sun, 0.05 * np.cbrt(np.prod(cell)), layout)
    cam = Camera(position=np.array([320.0, 60.0, 20.0]))
    cam.yaw, cam.pitch = math.pi, 0.25
    depth = np.ones((36, 64))
    run = lambda n: reference.march_shafts(depth, view_basis(cam, 16 / 9), cam.position, cam.near, cam.far, (128, 72),
                                           2, sun, np.ones(3), LightShaftSettings(steps=n, scattering=4e-4,
                                                                                  max_distance=500.0), tau)[..., 0]
    truth = run(256)
    return [(n, float(np.sqrt(np.mean((run(n) - truth) ** 2)) / truth.mean())) for n in steps]


def main() -> None:
    print(f"light_shafts pass, sunset {SIZE[0]}x{SIZE[1]}, GPU ms (mean of 30 frames):")
    for mode in ("screen", "march"):
        print(f"  {mode:6s} {pass_ms(mode):8.2f}")
    print("march error vs steps (relative RMSE of the in-scattered light vs 256 steps):")
    for n, e in step_errors():
        print(f"  {n:4d} steps  {100 * e:6.2f} %")


if __name__ == "__main__":
    main()
