"""Heterogeneous fog: image error against run time, texture vs procedural noise, 1-4 octaves.

The fog_valley scene (10,082-triangle terrain square and its far ring, sky, eq. 7 fog with g = 0.044
and the paper's 16³-128³ octaves) is rendered with each noise variant; RMSE is taken over the final
sRGB image (0-1 scale, uint8 quantisation floor ≈ 0.001) against the 4-octave *procedural* render, which evaluates the exact
periodic noise per pixel (float32 on the GPU; the float64 references agree with it to ~1e-6, see
tests/test_fog.py), so it is the highest-quality image this renderer makes. The 1-3 octave rows
show the truncation error of eq. (5); the texture rows add the trilinear-resampling error of storing
the noise at texels_per_cell samples per lattice cell. Time: the fog pass's GPU timer (ms) and the
whole frame (wall clock with glFinish). Writes out/bench_fog.png and the paper's figure presets
out/fog_valley_fig*.png.

    python benchmarks/bench_fog.py [--size 320x180] [--frames 8]
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from atmos.app import App
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless

import atmos.demos.fog_valley as fog_valley

OUT = Path(__file__).resolve().parents[1] / "out"
PAPER = ("Zdrojewska 2004, GeForce FX 5200, ~10,000 triangles, 4 texture octaves", 1000.0 / 20.0)


def render(gpu, size, frames, preset="fig6", **fields):
    """(image float 0-1, fog pass GPU ms, frame wall ms) after warm-up, at a fixed scene time."""
    app = App(gpu)
    settings = DemoSettings(size=size, headless=True)
    app.insert_resource(settings)           # the demo's systems read it, as under build_app
    fog = fog_valley.build(app, settings, fog_preset=preset)
    fog.configure(**fields)
    app.graph.timings_enabled = True        # the fog pass's timer query
    app.run_frames(3, dt=0.0)           # compile, make noise volumes
    gpu.ctx.finish()
    fog_ms, wall = [], []
    for _ in range(frames):
        t = time.perf_counter()
        app.update(0.0)
        gpu.ctx.finish()
        wall.append((time.perf_counter() - t) * 1e3)
        timing = app.graph.timings.get("fog")
        if timing:
            fog_ms.append(timing[0])
    image = gpu.read_pixels().astype(np.float64) / 255.0
    app.close()
    return image, float(np.median(fog_ms)) if fog_ms else float("nan"), float(np.median(wall))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="320x180")
    parser.add_argument("--frames", type=int, default=30)
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    OUT.mkdir(exist_ok=True)
    gpu = create_headless(size)
    print(f"renderer: {gpu.info().get('GL_RENDERER')}, {size[0]}x{size[1]}, median of {args.frames} frames")

    reference, _, _ = render(gpu, size, 1, noise="procedural", octaves=4)
    rows = []
    base = render(gpu, size, args.frames, mode="exp2")
    rows.append(("homogeneous exp2 (eq. 4)", "-", 0, float(np.sqrt(np.mean((base[0] - reference) ** 2))), base[1], base[2]))
    for noise, tpc in (("texture", 1), ("texture", 2), ("procedural", 1)):
        for octaves in (1, 2, 3, 4):
            image, fog_ms, frame_ms = render(gpu, size, args.frames, noise=noise, texels_per_cell=tpc, octaves=octaves)
            rmse = float(np.sqrt(np.mean((image - reference) ** 2)))
            label = f"{noise}" + (f" ({tpc} texel/cell)" if noise == "texture" else "")
            rows.append((label, str(tpc) if noise == "texture" else "-", octaves, rmse, fog_ms, frame_ms))

    print(f"\n{'variant':34s} {'octaves':>7s} {'RMSE':>8s} {'fog ms':>8s} {'frame ms':>9s} {'fps':>7s}")
    for label, _, octaves, rmse, fog_ms, frame_ms in rows:
        print(f"{label:34s} {octaves:7d} {rmse:8.4f} {fog_ms:8.2f} {frame_ms:9.2f} {1000 / frame_ms:7.1f}")
    print(f"{PAPER[0]:34s} {4:7d} {'-':>8s} {'-':>8s} {PAPER[1]:9.2f} {1000 / PAPER[1]:7.1f}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label in dict.fromkeys(r[0] for r in rows[1:]):
        sel = [r for r in rows if r[0] == label]
        ax.plot([r[4] for r in sel], [r[3] for r in sel], "o-", label=label)
        for r in sel:
            ax.annotate(str(r[2]), (r[4], r[3]), textcoords="offset points", xytext=(4, 4), fontsize=8)
    ax.plot([rows[0][4]], [rows[0][3]], "ks", label=rows[0][0])
    ax.set_xlabel("fog pass GPU ms per frame")
    ax.set_ylabel("image RMSE vs 4-octave procedural")
    ax.set_yscale("symlog", linthresh=1e-3)
    ax.set_title(f"heterogeneous fog (eq. 7, g=0.044), {size[0]}x{size[1]}, {gpu.info().get('GL_RENDERER')}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "bench_fog.png", dpi=110)
    print(f"\nplot: {OUT / 'bench_fog.png'}")

    from PIL import Image
    for name in fog_valley.PRESETS:
        image, _, _ = render(gpu, size, 1, preset=name)
        Image.fromarray((image * 255).round().astype(np.uint8)).save(OUT / f"fog_valley_{name}.png")
    print(f"presets: {OUT}/fog_valley_{{valley,fig6..fig10}}.png")
    gpu.release()


if __name__ == "__main__":
    main()
