"""Cloud contrast on screen: how much of the clouds' shading the camera keeps.

A plain script (``python benchmarks/bench_cloud_contrast.py [--size W H] [--frames N]``). For the
sunset, flight and weather demos (weather as it starts, fair) with each camera, ``--exposure fixed`` (the
plain exposure 1) and ``auto`` (the physical camera: metered EV100, bloom), it renders ``N`` frames and
takes the cloud pixels of the last (sky pixels, nothing drawn there, that clouds cover to alpha >= 0.9):
their displayed luminance's 10th and 90th percentiles (0..255), their ratio (the darker shading over
the brighter: lower is more contrast) and the share of cloud pixels above 230 (clipped to white).
"""
from __future__ import annotations

import argparse

import numpy as np

from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.render_core import LinearCapturePass
from atmos.runner import build_app

SCENES = ("sunset", "flight", "weather")


def cloud_contrast(name: str, exposure: str, size, frames: int) -> dict:
    gpu = create_headless(size)
    try:
        app = build_app(name, DemoSettings(size=size, headless=True, exposure=exposure), gpu)
        app.run_frames(frames, 1 / 30)
        hdr = app.read_linear()
        capture = next(p for p in app.graph.passes if isinstance(p, LinearCapturePass))
        depth = capture.depth[::-1]
        shown = gpu.read_pixels()[::-1, :, :3].astype(np.float64)
        app.close()
    finally:
        gpu.release()
    luma = shown @ np.array([0.2126, 0.7152, 0.0722])
    cloud = (depth >= 1.0) & (hdr[..., 3] >= 0.9)
    values = luma[cloud]
    if values.size < 50:
        return {"scene": name, "camera": exposure, "cloud_share": float(cloud.mean()), "p10": None, "p90": None,
                "ratio": None, "clipped": None}
    p10, p90 = np.percentile(values, [10, 90])
    return {"scene": name, "camera": exposure, "cloud_share": float(cloud.mean()), "p10": float(p10),
            "p90": float(p90), "ratio": float(p10 / max(p90, 1e-9)), "clipped": float((values > 230).mean())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, nargs=2, default=(480, 270))
    parser.add_argument("--frames", type=int, default=30)
    args = parser.parse_args()
    print(f"{'scene':10s} {'camera':7s} {'clouds':>7s} {'p10':>6s} {'p90':>6s} {'p10/p90':>8s} {'> 230':>6s}")
    for name in SCENES:
        for exposure in ("fixed", "auto"):
            r = cloud_contrast(name, exposure, tuple(args.size), args.frames)
            if r["ratio"] is None:
                print(f"{name:10s} {exposure:7s} {r['cloud_share']:7.1%}   (too few cloud pixels)")
                continue
            print(f"{name:10s} {exposure:7s} {r['cloud_share']:7.1%} {r['p10']:6.1f} {r['p90']:6.1f} {r['ratio']:8.2f} "
                  f"{r['clipped']:6.1%}")


if __name__ == "__main__":
    main()
