"""Cloud shading: error against the float64 exact reference versus ms per full shading pass.

A plain script (``python benchmarks/bench_shading.py [--shape NX NY NZ] [--repeats N]``). Methods:
shear-warp at full, half and quarter resolution, the per-voxel ray march, and the thesis's fixed-ratio
model (8-bit); volumes: smooth soft blobs and a blurred automaton cloud field; sun elevations 90, 60,
45, 30, 10 and 1 degrees (azimuth 30). GPU times: ctx.finish() before and after a whole pass (begin +
every slice), median of ``--repeats``. Prints a table, writes ``out/bench_shading.png`` (error vs ms)
and ``out/bench_shading_slices.png`` (a vertical cut of transmittance per method, to look at).
"""
from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np

from atmos.gpu import create_headless
from atmos.plugins.clouds.automaton import CloudAutomaton
from atmos.plugins.clouds.light import ShearWarpShader, raymarch, reference
from atmos.plugins.clouds.light.shear_warp import read_volume, upload_volume

THESIS_MS = 8.696          # sec. 8.2: full-resolution shading, 256x32x256, GeForce 8700M GT
ELEVATIONS = (90, 60, 45, 30, 10, 1)
AZIMUTH = 30.0
SIGMA = 0.25
METHODS = ("shear-warp x1", "shear-warp x2", "shear-warp x4", "raymarch", "thesis fixed-ratio")


def sun_direction(elevation: float) -> np.ndarray:
    e, a = math.radians(elevation), math.radians(AZIMUTH)
    return np.array([math.sin(a) * math.cos(e), math.sin(e), -math.cos(a) * math.cos(e)])


def blur(volume: np.ndarray, radius: int, passes: int = 2) -> np.ndarray:
    """Separable box blur (edge-clamped), ``passes`` times: close to a Gaussian."""
    out = volume.astype(np.float64)
    for _ in range(passes):
        for axis in range(3):
            padded = np.concatenate([np.repeat(np.take(out, [0], axis), radius, axis), out,
                                     np.repeat(np.take(out, [-1], axis), radius, axis)], axis)
            c = np.cumsum(padded, axis=axis)
            c = np.concatenate([np.zeros_like(np.take(c, [0], axis)), c], axis)
            n = out.shape[axis]
            out = (np.take(c, np.arange(2 * radius + 1, n + 2 * radius + 1), axis)
                   - np.take(c, np.arange(0, n), axis)) / (2 * radius + 1)
    return out


def smooth_volume(shape, rng) -> np.ndarray:
    grids = np.meshgrid(*[(np.arange(n) + 0.5) / n for n in shape], indexing="ij")
    out = np.zeros(shape)
    for _ in range(12):
        c = rng.random(3) * [1, 0.6, 1] + [0, 0.2, 0]
        r = rng.uniform(0.08, 0.2)
        out += np.exp(-((grids[0] - c[0]) ** 2 + ((grids[1] - c[1]) * shape[1] / shape[0] * 3) ** 2
                        + (grids[2] - c[2]) ** 2) / r ** 2)
    return (out / out.max()).astype(np.float32)


def automaton_volume(gpu, shape, steps: int = 40) -> np.ndarray:
    rng = np.random.default_rng(7)
    ca = CloudAutomaton(gpu, shape, seed=3)
    y = np.arange(shape[1])[None, :, None] / shape[1]
    band = np.exp(-((y - 0.45) / 0.2) ** 2) * np.ones(shape)
    ca.upload(rng.random(shape) < 0.3 * band, rng.random(shape) < 0.02 * band, np.zeros(shape, bool))
    for _ in range(steps):
        ca.step(p_ext=0.05, p_hum=(0.02 * band).astype(np.float32), p_act=(0.002 * band).astype(np.float32),
                shift=(1, 0))
    cld = ca.download()[2]
    ca.release()
    return blur(cld.astype(np.float64), 1).astype(np.float32)


def timed(ctx, run, repeats: int) -> tuple[float, object]:
    times, out = [], run()          # the first run compiles shaders: not timed
    for _ in range(repeats):
        ctx.finish()
        start = time.perf_counter()
        out = run()
        ctx.finish()
        times.append((time.perf_counter() - start) * 1e3)
    return float(np.median(times)), out


def run_methods(gpu, density, sun, repeats):
    """{method: (ms, transmittance on the full grid)}; upsampling of coarse results is not timed."""
    ctx = gpu.ctx
    texture = upload_volume(gpu, density)
    results = {}
    for name, scale, model in (("shear-warp x1", 1, "true-path"), ("shear-warp x2", 2, "true-path"),
                               ("shear-warp x4", 4, "true-path"), ("thesis fixed-ratio", 1, "fixed-ratio")):
        shader = ShearWarpShader(gpu, density.shape, scale=scale, model=model, levels=255 if model != "true-path" else 0)
        sigma = SIGMA
        ms, _ = timed(ctx, lambda: (shader.begin(texture, sun, sigma), shader.run_all()), repeats)
        coarse = read_volume(shader.result).astype(np.float64)
        results[name] = (ms, reference.upsample(coarse, density.shape) if scale > 1 else coarse)
        shader.release()
    target = ctx.texture3d(density.shape, 1, dtype="f4")
    ms, _ = timed(ctx, lambda: raymarch(gpu, texture, sun, SIGMA, target), max(1, repeats // 2))
    results["raymarch"] = (ms, read_volume(target).astype(np.float64))
    target.release()
    texture.release()
    return results


def thesis_size_ms(gpu, repeats):
    shape = (256, 32, 256)
    density = smooth_volume(shape, np.random.default_rng(1))
    texture = upload_volume(gpu, density)
    out = {}
    for scale in (1, 2):
        shader = ShearWarpShader(gpu, shape, scale=scale)
        out[scale], _ = timed(gpu.ctx, lambda: (shader.begin(texture, (0.2, 1, 0.1), SIGMA), shader.run_all()),
                              repeats)
        shader.release()
    texture.release()
    return out


def save_plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    markers = dict(zip(METHODS, "osD^v"))
    for ax, key, title in ((axes[0], 3, "mean |T - T_ref|"), (axes[1], 4, "max |T - T_ref|")):
        for method in METHODS:
            for volume, face in (("smooth", "full"), ("automaton", "none")):
                pts = [(r[5], r[key]) for r in rows if r[2] == method and r[0] == volume]
                ms, err = zip(*pts)
                ax.scatter(ms, np.maximum(err, 1e-7), marker=markers[method],
                           facecolors=None if face == "full" else "none",
                           edgecolors=f"C{METHODS.index(method)}", color=f"C{METHODS.index(method)}",
                           label=f"{method} ({volume})")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("ms per full shading pass (this machine)")
        ax.set_title(title)
        if key == 3:
            ax.axhline(0.005, color="grey", ls="--", lw=0.8)
    axes[1].legend(fontsize=7, loc="lower left")
    fig.suptitle("cloud shading: error vs run time, elevations 90..1 deg")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def save_slices(panels, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(panels), 1, figsize=(9, 1.4 * len(panels) + 0.5))
    for ax, (title, image) in zip(axes, panels):
        ax.imshow(image.T, origin="lower", cmap="magma" if title != "density" else "Blues", vmin=0,
                  vmax=max(1.0, float(image.max())) if title != "density" else None, aspect="auto")
        ax.set_title(title, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shape", type=int, nargs=3, default=(128, 32, 128))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", default="out")
    args = parser.parse_args()
    shape = tuple(args.shape)
    gpu = create_headless((16, 16))
    volumes = {"smooth": smooth_volume(shape, np.random.default_rng(0)), "automaton": automaton_volume(gpu, shape)}
    print(f"cloud shading, {shape[0]}x{shape[1]}x{shape[2]} voxels, sigma {SIGMA}/cell, azimuth {AZIMUTH} deg, "
          f"{gpu.ctx.info['GL_RENDERER']}")
    head = (f"{'volume':10s} {'elev':>5s} {'method':20s} {'mean err':>9s} {'max err':>9s} {'ms/pass':>9s} "
            f"{'vs march':>9s} {'goal':>14s}")
    print(head)
    print("-" * len(head))
    rows, panels = [], []
    for volume, density in volumes.items():
        for elevation in ELEVATIONS:
            sun = sun_direction(elevation)
            exact = reference.transmittance_exact(density, sun, SIGMA)
            results = run_methods(gpu, density, sun, args.repeats)
            march_ms = results["raymarch"][0]
            for method in METHODS:
                ms, t = results[method]
                err = np.abs(t - exact)
                goal = ""
                if method == "shear-warp x1":
                    ok = err.mean() <= 0.005 and march_ms >= 10 * ms
                    goal = f"{'met' if ok else 'MISSED'} (<.005,10x)"
                rows.append((volume, elevation, method, err.mean(), err.max(), ms))
                print(f"{volume:10s} {elevation:5d} {method:20s} {err.mean():9.5f} {err.max():9.5f} {ms:9.2f} "
                      f"{march_ms / ms:8.1f}x {goal:>14s}")
            if volume == "automaton" and elevation == 10:
                cut = shape[2] // 2
                panels = [("density", density[:, :, cut]), ("exact reference (float64)", exact[:, :, cut])]
                panels += [(f"{m}  (mean err {np.abs(results[m][1] - exact).mean():.4f})", results[m][1][:, :, cut])
                           for m in METHODS]
    os.makedirs(args.out, exist_ok=True)
    save_plot(rows, os.path.join(args.out, "bench_shading.png"))
    save_slices(panels, os.path.join(args.out, "bench_shading_slices.png"))
    thesis = thesis_size_ms(gpu, args.repeats)
    print(f"\nfull shading pass at the thesis's 256x32x256: ours {thesis[1]:.2f} ms (x1), {thesis[2]:.2f} ms (x2) "
          f"on {gpu.ctx.info['GL_RENDERER']}; thesis sec. 8.2: {THESIS_MS} ms (x1), ~2.2 ms (x2, '460 per "
          f"second') on a GeForce 8700M GT")
    print(f"wrote {args.out}/bench_shading.png and {args.out}/bench_shading_slices.png")
    gpu.ctx.error
    gpu.release()


if __name__ == "__main__":
    main()
