"""Frame-to-frame stability of both cloud renderers with a still camera (issues 12 and 15).

A plain script (``python3 benchmarks/bench_cloud_stability.py [--frames N] [--size WxH]``): the
``sunset`` demo's scene (its clouds evolving, 3 slices per frame, the sun moving with the clock) seen
by a still camera toward the sun, once per renderer mode: the sprites, the march at its defaults
(resolution 2, reprojection, jitter) and at resolution 1 with and without jitter. Per frame it records
the mean absolute change of the 8-bit picture and the shown interpolation position (step + t). The
legit part of the change is the one of the march at resolution 1 without jitter (the clouds evolving,
nothing from the renderer); a mode's own noise is the frame-to-frame change of its difference from
those frames. Prints mean, median, max/median (a periodic spike: max/median far above 1) and plots
everything to ``out/st_stability.png``. ``--frozen``: the clouds, their wind and the sun stopped, so
all the change is the renderer's (temporal noise at 1:1): per mode the mean change over the last half
of the frames and the speckle of the last frame (mean |picture − its 3×3 box blur|, 8-bit levels; the
jitter's pattern, frozen or not, is most of it), no plot.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from atmos.app import App
from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.demos._cloudscape import _renderers, build_cloudscape
from atmos.gpu import create_headless
from atmos.lighting import Sun
from atmos.plugins.clouds import CloudSimulation

ROOT = Path(__file__).resolve().parents[1]
MODES = {"sprites": ("sprites", {}),
         "march r2 reproj": ("march", {}),
         "march r1 jitter": ("march", dict(resolution=1)),
         "march r1 no jitter (legit)": ("march", dict(resolution=1, jitter=False))}
LEGIT = "march r1 no jitter (legit)"


def sunset_frames(gpu, clouds: str, fields: dict, frames: int, frozen: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(frames + 1 images (h, w, 3) float64, shown step + t per image) of the sunset scene, still camera;
    ``frozen``: the clouds, their wind and the sun stopped (all the change is the renderer's)."""
    app = App(gpu)
    build_cloudscape(app, DemoSettings(size=gpu.size, headless=True, clouds=clouds), hours=19.2,
                     speed=0.0 if frozen else 0.01, cloud_density=150, warmup_steps=12, haze=True,
                     **(dict(wind=(0.0, 0.0, 0.0)) if frozen else {}))
    if fields:
        _renderers(app)[1].configure(**fields)
    app.startup()
    cam = app.resource(Camera)
    cam.position = np.array([0.0, 320.0, 0.0])
    sun = app.resource(Sun).direction
    cam.yaw, cam.pitch = math.atan2(sun[0], -sun[2]) + 0.35, math.radians(7.0)
    sim = app.resource(CloudSimulation)
    if frozen:
        app.frames.remove(sim.job)          # the simulation paused: the shown step and t stay
    images, shown = [], []
    for _ in range(frames + 1):
        app.update(1 / 60)
        images.append(gpu.read_pixels().astype(np.float64))
        shown.append(sim.job.step + sim.job.progress)
    app.close()
    return np.stack(images), np.array(shown)


def speckle(image: np.ndarray) -> float:
    """Mean |image − its 3×3 box blur| (8-bit levels) over the interior pixels: fine spatial noise."""
    h, w = image.shape[:2]
    blur = sum(image[1 + j:h - 1 + j, 1 + i:w - 1 + i] for j in (-1, 0, 1) for i in (-1, 0, 1)) / 9.0
    return float(np.abs(image[1:h - 1, 1:w - 1] - blur).mean())


def change(images: np.ndarray) -> np.ndarray:
    """Mean |frame − previous| per frame (8-bit levels)."""
    return np.abs(np.diff(images, axis=0)).mean(axis=(1, 2, 3))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--size", default="320x180")
    parser.add_argument("--modes", default=",".join(MODES), help="comma-separated subset of: " + ", ".join(MODES))
    parser.add_argument("--frozen", action="store_true", help="clouds, wind and sun stopped: the renderer's own noise")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    modes = [m.strip() for m in args.modes.split(",")]
    if LEGIT not in modes:
        modes.append(LEGIT)
    gpu = create_headless(size)
    print(f"renderer: {gpu.ctx.info['GL_RENDERER']}, sunset {size[0]}x{size[1]}, still camera, {args.frames} frames"
          + (", frozen clouds" if args.frozen else ""))
    runs = {m: sunset_frames(gpu, MODES[m][0], MODES[m][1], args.frames, frozen=args.frozen) for m in modes}
    gpu.release()
    if args.frozen:
        for m in modes:
            c = change(runs[m][0])
            print(f"{m:28s} change over the last {len(c) // 2} frames {c[len(c) // 2:].mean():.3f} (max "
                  f"{c[len(c) // 2:].max():.3f}), speckle of the last frame {speckle(runs[m][0][-1]):.3f}")
        return
    legit = runs[LEGIT][0]
    rows = {}
    for m in modes:
        images, shown = runs[m]
        c = change(images)
        own = change(images - legit) if m != LEGIT else np.zeros_like(c)
        med = float(np.median(c))
        rows[m] = (c, own, shown)
        print(f"{m:28s} change mean {c.mean():.3f} median {med:.3f} max/median {c.max() / max(med, 1e-9):.2f} | "
              f"own noise mean {own.mean():.3f} | rotations {int(np.floor(shown[-1]) - np.floor(shown[0]))}, "
              f"t step mean {np.diff(shown).mean():.4f} min {np.diff(shown).min():.4f} max {np.diff(shown).max():.4f}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (top, mid, bottom) = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    for m, (c, own, shown) in rows.items():
        top.plot(c, label=m)
        if m != LEGIT:
            mid.plot(own, label=m)
        bottom.plot(np.diff(shown), label=m)
    for k in np.nonzero(np.diff(np.floor(rows[LEGIT][2])))[0]:
        for ax in (top, mid, bottom):
            ax.axvline(k, color="grey", lw=0.5, ls=":")
    top.set_ylabel("mean |Δ| per frame (8-bit)")
    mid.set_ylabel("own noise: |Δ(mode − legit)|")
    bottom.set_ylabel("step + t increment")
    bottom.set_xlabel("frame (dotted: a texture-set rotation)")
    top.legend(fontsize=8)
    top.set_title(f"sunset, still camera, {size[0]}x{size[1]}: frame-to-frame change per renderer")
    (ROOT / "out").mkdir(exist_ok=True)
    fig.tight_layout()
    fig.savefig(ROOT / "out" / "st_stability.png", dpi=100)
    print(f"plot: {ROOT / 'out' / 'st_stability.png'}")


if __name__ == "__main__":
    main()
