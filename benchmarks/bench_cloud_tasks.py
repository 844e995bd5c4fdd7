"""Cloud smoothing and density-map time at 256x32x256 beside the thesis's Table 8.1.

A plain script (``python3 benchmarks/bench_cloud_tasks.py [--runs N] [--shape NX NY NZ]``) that
prints ms per stage (median of N runs, ctx.finish() before and after each) for the whole volume
and per slice when split into ``--slices`` z slices, and writes ``out/bench_cloud_tasks.png``:
the top-view density map, one height band, the max map over the sprite-group grid and a
vertical cut through the smoothed volume.
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from atmos.gpu import create_headless
from atmos.plugins.clouds.automaton import CloudAutomaton
from atmos.plugins.clouds import DensityMaps, Smoother, read_volume, reference, slice_range

ROOT = Path(__file__).resolve().parents[1]
THESIS_MS = {"smoothing": 6.024, "density maps": 0.588, "region volume": 5.26}  # Table 8.1, 8700M GT, 256x32x256


def cloud_field(rng, shape, blobs: int = 14) -> np.ndarray:
    """cld of a few flattened, ragged ellipsoids (leaves most sprite-group segments empty)."""
    nx, ny, nz = shape
    x, y, z = np.meshgrid(*(np.arange(n) + 0.5 for n in shape), indexing="ij")
    cld = np.zeros(shape, bool)
    for _ in range(blobs):
        c = rng.uniform((0, ny * 0.3, 0), (nx, ny * 0.7, nz))
        r = rng.uniform((nx * 0.03, ny * 0.15, nz * 0.03), (nx * 0.1, ny * 0.35, nz * 0.1))
        cld |= (((x - c[0]) / r[0]) ** 2 + ((y - c[1]) / r[1]) ** 2 + ((z - c[2]) / r[2]) ** 2) < 1
    return cld & (rng.random(shape) < 0.7)


def median_ms(ctx, run, runs: int) -> float:
    times = []
    for _ in range(runs):
        ctx.finish()
        start = time.perf_counter()
        run()
        ctx.finish()
        times.append((time.perf_counter() - start) * 1e3)
    return statistics.median(times)


def region_volume_ms(gpu, shape, runs: int) -> dict[int, float]:
    """ms to render the region volume (and its probabilities) from n random weather ellipsoids."""
    from atmos.plugins.clouds.weather import RegionVolume, WeatherSettings
    rng = np.random.default_rng(1)
    region = RegionVolume(gpu, shape)
    params = WeatherSettings(volume_shape=shape)
    result = {}
    for n in (100, 1000):
        e = np.zeros((n, 8), np.float32)
        e[:, :3] = rng.uniform(0, 1, (n, 3)) * shape
        e[:, 3] = rng.uniform(0, 6.3, n)
        e[:, 4:7] = rng.uniform((6, 2, 6), (20, 6, 20), (n, 3))

        def run():
            region.render(e)
            region.probabilities(params)
        run()
        result[n] = median_ms(gpu.ctx, run, runs)
    region.release()
    return result


def plot(maps: DensityMaps, density: np.ndarray, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sums, maxes = maps.read_sums(), maps.read_max_maps()
    band = int(np.argmax(sums[1:].sum(axis=(1, 2)))) + 1
    fig, axes = plt.subplots(1, 4, figsize=(17, 4.4))
    images = [(sums[0].T, "density map: all heights (top view)"),
              (sums[band].T, f"band {band - 1} (heights {(band - 1) * maps.band_height}.."
                             f"{band * maps.band_height - 1})"),
              (maxes[0].T, f"max map {maps.grid[0]}x{maps.grid[1]} (0 = skipped)"),
              (density[:, :, density.shape[2] // 2].T, "smoothed density, cut z = nz/2")]
    for ax, (img, title) in zip(axes, images):
        shown = ax.imshow(img, origin="lower", cmap="magma", interpolation="nearest", aspect="auto")
        ax.set_title(title, fontsize=9)
        fig.colorbar(shown, ax=ax, fraction=0.046)
    axes[3].set_xlabel("x")
    axes[3].set_ylabel("y (height)")
    for ax in axes[:2]:
        gx, gz = maps.group_size
        for k in range(1, maps.grid[0]):
            ax.axvline(k * gx - 0.5, color="cyan", lw=0.4)
        for k in range(1, maps.grid[1]):
            ax.axhline(k * gz - 0.5, color="cyan", lw=0.4)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)


def measure(gpu, shape, runs: int, slices: int, references: bool = True, plot_to: Path | None = None) -> list[dict]:
    """Rows (stage, whole_ms, slice_ms for 1/``slices`` of the volume, thesis_ms, numpy_ms) for the
    smoothing (packed f2, packed f4, cell f2), the density maps and the region volume (100 and 1000
    ellipsoids) at ``shape``; ``references``: time the numpy references too; ``plot_to``: write the
    maps' picture there."""
    ctx = gpu.ctx
    ca = CloudAutomaton(gpu, shape, layout="packed")
    cld = cloud_field(np.random.default_rng(0), shape)
    ca.upload(np.zeros(shape, bool), np.zeros(shape, bool), cld)
    maps = DensityMaps(gpu, shape, band_height=4, group_size=(32, 32))
    rows, density = [], None
    z0, z1 = slice_range(shape[2], 0, slices)
    for layout, dtype in (("packed", "f2"), ("packed", "f4"), ("cell", "f2")):
        state = ca if layout == "packed" else CloudAutomaton(gpu, shape, layout="cell")
        if state is not ca:
            state.upload(np.zeros(shape, bool), np.zeros(shape, bool), cld)
        smoother = Smoother.for_automaton(state)
        texture = smoother.create_texture(dtype)
        smoother.run(state.state_buffer, texture)           # warm-up: compiles
        whole = median_ms(ctx, lambda: smoother.run(state.state_buffer, texture), runs)
        part = median_ms(ctx, lambda: smoother.run(state.state_buffer, texture, z0, z1), runs)
        ref = None
        if density is None:
            if references:
                start = time.perf_counter()
                reference.smooth(cld, min_density=smoother.min_density(dtype))
                ref = (time.perf_counter() - start) * 1e3
            density = read_volume(texture)
            maps.run(texture)
            dm_whole = median_ms(ctx, lambda: maps.run(texture), runs)
            dm_part = median_ms(ctx, lambda: maps.run(texture, z0, z1), runs)
            dm_ref = None
            if references:
                start = time.perf_counter()
                reference.density_maps(density, maps.band_height, maps.group_size)
                dm_ref = (time.perf_counter() - start) * 1e3
            dm_tex = texture
        rows.append({"stage": f"smoothing r=1 tent, {layout}, {dtype}", "whole_ms": whole, "slice_ms": part,
                     "thesis_ms": THESIS_MS["smoothing"], "numpy_ms": ref})
        smoother.release()
        if texture is not dm_tex:
            texture.release()
        if state is not ca:
            state.release()
    rows.append({"stage": f"density maps, {maps.bands} bands, {maps.grid[0]}x{maps.grid[1]}", "whole_ms": dm_whole,
                 "slice_ms": dm_part, "thesis_ms": THESIS_MS["density maps"], "numpy_ms": dm_ref})
    for n, ms in region_volume_ms(gpu, shape, runs).items():
        rows.append({"stage": f"region volume, {n} ellipsoids", "whole_ms": ms, "slice_ms": None,
                     "thesis_ms": THESIS_MS["region volume"], "numpy_ms": None})
    maxes = maps.read_max_maps()
    rows.append({"stage": "max maps read back (bytes)", "whole_ms": None, "slice_ms": None, "thesis_ms": None,
                 "numpy_ms": None, "bytes": int(maxes.nbytes),
                 "columns_drawn": f"{(maxes[0] > 0).sum()} of {maxes[0].size}",
                 "band_segments_drawn": f"{(maxes[1:] > 0).sum()} of {maxes[1:].size}"})
    if plot_to is not None:
        plot(maps, density, plot_to)
    dm_tex.release()
    maps.release()
    ca.release()
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shape", type=int, nargs=3, default=(256, 32, 256))
    parser.add_argument("--runs", type=int, default=7, help="timed runs per case (median)")
    parser.add_argument("--slices", type=int, default=32, help="z slices for the sliced rows")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "bench_cloud_tasks.png")
    args = parser.parse_args()
    shape = tuple(args.shape)
    gpu = create_headless((16, 16))
    print(f"cloud stages, {shape[0]}x{shape[1]}x{shape[2]} cells, {gpu.ctx.info['GL_RENDERER']}, "
          f"median of {args.runs} runs")
    head = (f"{'stage':34s} {'whole ms':>9s} {f'1/{args.slices} slice ms':>16s} {'thesis ms':>10s} "
            f"{'numpy ms':>9s}")
    print(head)
    print("-" * len(head))
    rows = measure(gpu, shape, args.runs, args.slices, plot_to=args.out)
    for r in rows:
        if r["whole_ms"] is None:
            print(f"max maps read back: {r['bytes']} bytes; segments to draw: {r['columns_drawn']} columns, "
                  f"{r['band_segments_drawn']} band segments")
            continue
        part = "" if r["slice_ms"] is None else f"{r['slice_ms']:16.3f}"
        ref = "" if r["numpy_ms"] is None else f"{r['numpy_ms']:9.0f}"
        print(f"{r['stage']:34s} {r['whole_ms']:9.2f} {part:>16s} {r['thesis_ms']:10.3f} {ref:>9s}")
    print("thesis Table 8.1 (GeForce 8700M GT, pixel shaders, 256x32x256): volume smoothing "
          "6.024 ms, density map computation 0.588 ms, region volume 5.26 ms")
    print(f"wrote {args.out}")
    gpu.release()


if __name__ == "__main__":
    main()
