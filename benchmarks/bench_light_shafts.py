"""Light shafts: frame cost of the marched shafts, the froxel volume's and the screen-space ones in the
sunset demo (one run, this machine), and the error of the march vs its step count and of the froxel
volume vs its size, per frame and with its temporal history, against a 256-step march (float64
references, two cloud slabs with a gap, looking along it). Prints numbers; `.venv/bin/python benchmarks/bench_light_shafts.py`."""
from __future__ import annotations

import math

import numpy as np

from atmos import create_headless
from atmos.camera import Camera, view_basis
from atmos.demo_registry import DemoSettings
from atmos.froxels import HISTORY_BLEND, froxel_jitter
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.shadows.reference import sun_optical_depth
from atmos.plugins.light_shafts import LightShaftSettings, LightShaftsPass, reference
from atmos.runner import build_app

SIZE = (640, 360)
FROXEL_SIZES = ((8, 5, 16), (16, 9, 32), (16, 9, 64), (32, 18, 64), (64, 36, 4), (64, 36, 8), (64, 36, 16), (64, 36, 64),
                (64, 36, 128), (128, 72, 8))
HISTORY_FRAMES = 16       # still frames the froxel volume's history averages in the error table


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


def media_ms(fuse: bool, frames: int = 30, haze: str = "fog") -> tuple[float, float]:
    """(GPU ms of the media passes + the shafts', passes kept) in sunset with ``haze`` (fog, air, both), the
    froxels' apply compositing the media (``fuse``) or the media in their own passes before it."""
    LightShaftsPass.fuse_media = fuse
    gpu = create_headless(SIZE)
    app = build_app("sunset", DemoSettings(size=SIZE, headless=True, haze=haze), gpu)
    try:
        app.graph.timings_enabled = True
        app.run_frames(5, 1 / 30)
        total = 0.0
        for _ in range(frames):
            app.run_frames(1, 1 / 30)
            total += sum(app.graph.timings[name][0] for name in ("fog", "aerial_perspective", "light_shafts")
                         if name in app.graph.timings)
        return total / frames, len(app.graph.compile().kept)
    finally:
        LightShaftsPass.fuse_media = True
        app.close()
        gpu.release()


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


def accumulated(volume_of, frames: int = HISTORY_FRAMES, blend: float = HISTORY_BLEND) -> np.ndarray:
    """What FroxelHistory holds after ``frames`` frames of a still view: the volumes ``volume_of(jitter)`` at
    the middle, then at frames 1.., each blended in with weight max(1 / (n + 1), blend)."""
    out = None
    for n in range(frames):
        volume = volume_of(0.5 if n == 0 else froxel_jitter(n))
        out = volume if out is None else out + max(1.0 / (n + 1), blend) * (volume - out)
    return out


def froxel_errors(sizes=FROXEL_SIZES) -> list[tuple[tuple, float, float, float]]:
    """Per froxel volume (W, H, D) over a 128 × 72 image: (size, relative RMSE of each pixel's in-scattered
    light, and after a 3x3 blur, and with the temporal history after HISTORY_FRAMES still frames) against a
    256-step march per pixel (no jitter: the pixel's own ray)."""
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
        def volume_of(jitter, size=size):
            return reference.froxel_shafts(cam.position, basis, size, sun, np.ones(3), settings, tau, jitter)
        def image_of(volume):
            return reference.froxel_apply(volume, np.zeros((72, 128, 3)), np.ones((72, 128)), basis, cam.near,
                                          cam.far, settings)[..., 0]
        image = image_of(volume_of(0.5))
        rmse = lambda a, b: float(np.sqrt(np.mean((a - b) ** 2)) / b.mean())
        rows.append((size, rmse(image, truth), rmse(box3(image), box3(truth)),
                     rmse(image_of(accumulated(volume_of)), truth)))
    return rows


MOTIONS = {"turning 0.5 deg a frame": (math.radians(0.5), 0.0), "walking 2 m a frame": (0.0, 2.0)}


def motion_errors(sizes=((64, 36, 16), (128, 72, 8)), frames: int = 12) -> list[tuple[str, tuple, float, float]]:
    """Per camera motion (MOTIONS: yaw and forward step per frame) and froxel volume over a 128 × 72 image:
    (motion, size, relative RMSE of one frame's slice middles, of the history's output; both the mean over
    the last half of ``frames``) against a 256-step march per pixel of each frame's view: what the history
    (:func:`atmos.froxels.history_reference`, jittered slices reprojected) costs or gains while the view moves."""
    from atmos.froxels import froxel_knee, history_reference
    tau, sun, start = gap_scene()
    settings = LightShaftSettings(scattering=4e-4, max_distance=500.0)
    march = LightShaftSettings(steps=256, scattering=4e-4, max_distance=500.0)
    knee = froxel_knee(settings.max_distance)
    rmse = lambda a, b: float(np.sqrt(np.mean((a - b) ** 2)) / b.mean())
    rows = []
    for name, (turn, step) in MOTIONS.items():
        views = []
        for n in range(frames):
            ahead = start.forward() * np.array([1.0, 0.0, 1.0])
            cam = Camera(position=start.position + step * n * ahead / np.linalg.norm(ahead))
            cam.yaw, cam.pitch = start.yaw + turn * n, start.pitch
            views.append(cam)
        saved = reference.march_jitter
        reference.march_jitter = lambda w, h: np.full((h, w), 0.5)
        try:
            truths = [reference.march_shafts(np.ones((72, 128)), view_basis(c, 16 / 9), c.position, c.near, c.far,
                                             (128, 72), 1, sun, np.ones(3), march, tau)[..., 0] for c in views]
        finally:
            reference.march_jitter = saved
        for size in sizes:
            history, prev, single, kept = None, None, [], []
            for n, cam in enumerate(views):
                basis = view_basis(cam, 16 / 9)
                image_of = lambda v: reference.froxel_apply(v, np.zeros((72, 128, 3)), np.ones((72, 128)), basis,
                                                            cam.near, cam.far, settings)[..., 0]
                middle = reference.froxel_shafts(cam.position, basis, size, sun, np.ones(3), settings, tau)
                fresh = middle if n == 0 else reference.froxel_shafts(cam.position, basis, size, sun, np.ones(3),
                                                                      settings, tau, froxel_jitter(n))
                history = history_reference(fresh, history, basis, cam.position, *(prev or (basis, cam.position)),
                                            settings.max_distance, knee, max(1.0 / (n + 1), HISTORY_BLEND))
                prev = (basis, cam.position)
                if n >= frames // 2:
                    single.append(rmse(image_of(middle), truths[n]))
                    kept.append(rmse(image_of(history), truths[n]))
            rows.append((name, size, float(np.mean(single)), float(np.mean(kept))))
    return rows


def main() -> None:
    print(f"light_shafts pass, sunset {SIZE[0]}x{SIZE[1]}, GPU ms (mean of 30 frames):")
    for mode in ("screen", "march"):
        print(f"  {mode:6s}            {pass_ms(mode):8.2f}")
    for froxels in ((40, 23, 32), (80, 45, 64), (160, 90, 64)):
        print(f"  froxels {'x'.join(map(str, froxels)):>10s} {pass_ms('march', froxels=froxels):8.2f}")
    print(f"the media and the shafts, sunset {SIZE[0]}x{SIZE[1]}, GPU ms of the fog, air and shafts passes (mean of "
          "30 frames), passes kept:")
    for haze in ("fog", "air", "both"):
        for fuse, name in ((False, "their passes, then the apply"), (True, "the apply composites them")):
            ms, kept = media_ms(fuse, haze=haze)
            print(f"  {haze:5s} {name:30s} {ms:8.2f}   {kept} passes")
    print("froxel volume error vs size, 128x72 pixels (relative RMSE of the in-scattered light vs a 256-step")
    print("march per pixel; per pixel, after a 3x3 blur, and one frame's slice middles against the history of")
    print(f"{HISTORY_FRAMES} still frames of jittered slices, froxel_history {HISTORY_BLEND}):")
    for size, e, blurred, history in froxel_errors():
        print(f"  {'x'.join(map(str, size)):>10s}  {100 * e:6.2f} %   blurred {100 * blurred:6.2f} %   "
              f"history {100 * history:6.2f} %")
    print("froxel volume error while the view moves (relative RMSE vs a 256-step march of each frame's view,")
    print("mean over the last 6 of 12 frames; one frame's slice middles against the reprojected history):")
    for name, size, single, kept in motion_errors():
        print(f"  {name:24s} {'x'.join(map(str, size)):>10s}  {100 * single:6.2f} %   history {100 * kept:6.2f} %")
    print("march error vs steps (relative RMSE of the in-scattered light vs 256 steps; blue-noise offsets,")
    print("per texel and after a 3x3 blur; white-noise offsets after the blur):")
    for n, e, blurred, white in step_errors():
        print(f"  {n:4d} steps  {100 * e:6.2f} %   blurred {100 * blurred:6.2f} %   white, blurred {100 * white:6.2f} %")


if __name__ == "__main__":
    main()
