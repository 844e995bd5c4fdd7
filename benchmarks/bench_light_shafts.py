"""Light shafts: frame cost of the marched shafts, the froxel volume's and the screen-space ones in the
sunset demo (one run, this machine), and the error of the march vs its step count and of the froxel
volume vs its size against a 256-step march (float64 references, two cloud slabs with a gap, looking
along it). Prints numbers; `.venv/bin/python benchmarks/bench_light_shafts.py`."""
from __future__ import annotations

import math

import numpy as np

from atmos import create_headless
from atmos.camera import Camera, view_basis
from atmos.demo_registry import DemoSettings
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.shadows.reference import sun_optical_depth
from atmos.plugins.light_shafts import LightShaftSettings, LightShaftsPass, reference
from atmos.runner import build_app

SIZE = (640, 360)
FROXEL_SIZES = ((8, 5, 16), (16, 9, 32), (16, 9, 64), (32, 18, 64), (64, 36, 64), (64, 36, 128))


def pass_ms(mode: str, frames: int = 30, froxels=None) -> float:
    gpu = create_headless(SIZE)
    app = build_app("sunset", DemoSettings(size=SIZE, headless=True), gpu)
    next(p for p in app.graph.passes if isinstance(p, LightShaftsPass)).plugin.configure(mode=mode, froxels=froxels)
    app.graph.timings_enabled = True
    app.run_frames(5, 1 / 30)
    total = 0.0
    for _ in range(frames):
        app.run_frames(1, 1 / 30)
        total += app.graph.timings["light_shafts"][0]
    app.close()
    gpu.release()
    return total / frames


def white_jitter(w: int, h: int) -> np.ndarray:
    """The offsets the march took before its blue noise: lowbias32 of x + 65536 y, 24 bits (white noise)."""
    from atmos.hashing import lowbias32
    x, y = np.meshgrid(np.arange(w, dtype=np.uint64), np.arange(h, dtype=np.uint64))
    return (lowbias32((x + 65536 * y) & 0xFFFFFFFF) >> np.uint32(8)).astype(np.float64) / 16777216.0


def box3(image) -> np.ndarray:
    """A 3x3 box blur (edges clamped): roughly what the upsample to full resolution and the eye average."""
    p = np.pad(image, 1, mode="edge")
    return sum(p[1 + i:p.shape[0] - 1 + i, 1 + j:p.shape[1] - 1 + j] for i in (-1, 0, 1) for j in (-1, 0, 1)) / 9.0


def gap_scene():
    """(the sun's optical depth through two cloud slabs with a gap, unit sun direction, camera looking
    along the gap)."""
    shape, cell = (32, 4, 32), (20.0, 25.0, 20.0)
    volume = np.zeros(shape)
    volume[2:14] = volume[18:30] = 1.0
    sums = volume.sum(axis=1)
    layout = CloudLayout(shape, cell, (0.0, 0.0), 200.0, (8, 8), 0.0)
    sun = np.array([0.0, 1.0, 0.25]) / math.hypot(1.0, 0.25)
    tau = lambda p: sun_optical_depth(p, sums, sums, 0.0, sun, 0.05 * np.cbrt(np.prod(cell)), layout)
    cam = Camera(position=np.array([320.0, 60.0, 20.0]))
    cam.yaw, cam.pitch = math.pi, 0.25
    return tau, sun, cam


def step_errors(steps=(4, 8, 16, 24, 48, 128)) -> list[tuple[int, float, float, float]]:
    """Per step count: (steps, relative RMSE per texel, after a 3x3 blur, after a 3x3 blur with white-noise
    offsets) against 256 steps (blurred alike)."""
    tau, sun, cam = gap_scene()
    depth = np.ones((36, 64))
    run = lambda n: reference.march_shafts(depth, view_basis(cam, 16 / 9), cam.position, cam.near, cam.far, (128, 72),
                                           2, sun, np.ones(3), LightShaftSettings(steps=n, scattering=4e-4,
                                                                                  max_distance=500.0), tau)[..., 0]
    truth = run(256)
    rmse = lambda image, want=truth: float(np.sqrt(np.mean((image - want) ** 2)) / want.mean())
    rows = []
    for n in steps:
        image = run(n)
        saved = reference.march_jitter
        reference.march_jitter = white_jitter
        try:
            white = run(n)
        finally:
            reference.march_jitter = saved
        rows.append((n, rmse(image), rmse(box3(image), box3(truth)), rmse(box3(white), box3(truth))))
    return rows


def froxel_errors(sizes=FROXEL_SIZES) -> list[tuple[tuple, float, float]]:
    """Per froxel volume (W, H, D) over a 128 × 72 image: (size, relative RMSE of each pixel's in-scattered
    light, and after a 3x3 blur) against a 256-step march per pixel (no jitter: the pixel's own ray)."""
    tau, sun, cam = gap_scene()
    settings = LightShaftSettings(scattering=4e-4, max_distance=500.0)
    basis = view_basis(cam, 16 / 9)
    saved = reference.march_jitter
    reference.march_jitter = lambda w, h: np.full((h, w), 0.5)
    try:
        truth = reference.march_shafts(np.ones((72, 128)), basis, cam.position, cam.near, cam.far, (128, 72), 1, sun,
                                       np.ones(3), LightShaftSettings(steps=256, scattering=4e-4, max_distance=500.0),
                                       tau)[..., 0]
    finally:
        reference.march_jitter = saved
    rows = []
    for size in sizes:
        volume = reference.froxel_shafts(cam.position, basis, size, sun, np.ones(3), settings, tau)
        image = reference.froxel_apply(volume, np.zeros((72, 128, 3)), np.ones((72, 128)), basis, cam.near, cam.far,
                                       settings)[..., 0]
        rmse = lambda a, b: float(np.sqrt(np.mean((a - b) ** 2)) / b.mean())
        rows.append((size, rmse(image, truth), rmse(box3(image), box3(truth))))
    return rows


def main() -> None:
    print(f"light_shafts pass, sunset {SIZE[0]}x{SIZE[1]}, GPU ms (mean of 30 frames):")
    for mode in ("screen", "march"):
        print(f"  {mode:6s}            {pass_ms(mode):8.2f}")
    for froxels in ((40, 23, 32), (80, 45, 64), (160, 90, 64)):
        print(f"  froxels {'x'.join(map(str, froxels)):>10s} {pass_ms('march', froxels=froxels):8.2f}")
    print("froxel volume error vs size, 128x72 pixels (relative RMSE of the in-scattered light vs a 256-step")
    print("march per pixel; per pixel and after a 3x3 blur):")
    for size, e, blurred in froxel_errors():
        print(f"  {'x'.join(map(str, size)):>10s}  {100 * e:6.2f} %   blurred {100 * blurred:6.2f} %")
    print("march error vs steps (relative RMSE of the in-scattered light vs 256 steps; blue-noise offsets,")
    print("per texel and after a 3x3 blur; white-noise offsets after the blur):")
    for n, e, blurred, white in step_errors():
        print(f"  {n:4d} steps  {100 * e:6.2f} %   blurred {100 * blurred:6.2f} %   white, blurred {100 * white:6.2f} %")


if __name__ == "__main__":
    main()
