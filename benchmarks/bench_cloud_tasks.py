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
from atmos.automaton import CloudAutomaton
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
    from atmos.plugins.weather import RegionVolume, WeatherSettings
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shape", type=int, nargs=3, default=(256, 32, 256))
    parser.add_argument("--runs", type=int, default=7, help="timed runs per case (median)")
    parser.add_argument("--slices", type=int, default=32, help="z slices for the sliced rows")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "bench_cloud_tasks.png")
    args = parser.parse_args()
    shape = tuple(args.shape)
    gpu = create_headless((16, 16))
    ctx = gpu.ctx
    ca = CloudAutomaton(gpu, shape, layout="packed")
    cld = cloud_field(np.random.default_rng(0), shape)
    ca.upload(np.zeros(shape, bool), np.zeros(shape, bool), cld)
    maps = DensityMaps(gpu, shape, band_height=4, group_size=(32, 32))
    print(f"cloud stages, {shape[0]}x{shape[1]}x{shape[2]} cells, {cld.mean():.1%} cld, "
          f"{ctx.info['GL_RENDERER']}, median of {args.runs} runs")
    head = (f"{'stage':34s} {'whole ms':>9s} {f'1/{args.slices} slice ms':>16s} {'thesis ms':>10s} "
            f"{'numpy ms':>9s}")
    print(head)
    print("-" * len(head))
    density = None
    for layout, dtype in (("packed", "f2"), ("packed", "f4"), ("cell", "f2")):
        state = ca if layout == "packed" else CloudAutomaton(gpu, shape, layout="cell")
        if state is not ca:
            state.upload(np.zeros(shape, bool), np.zeros(shape, bool), cld)
        smoother = Smoother.for_automaton(state)
        texture = smoother.create_texture(dtype)
        smoother.run(state.state_buffer, texture)           # warm-up: compiles
        whole = median_ms(ctx, lambda: smoother.run(state.state_buffer, texture), args.runs)
        z0, z1 = slice_range(shape[2], 0, args.slices)
        part = median_ms(ctx, lambda: smoother.run(state.state_buffer, texture, z0, z1), args.runs)
        ref = ""
        if density is None:
            start = time.perf_counter()
            reference.smooth(cld, min_density=smoother.min_density(dtype))
            ref = f"{(time.perf_counter() - start) * 1e3:9.0f}"
            density = read_volume(texture)
            maps.run(texture)
            dm_whole = median_ms(ctx, lambda: maps.run(texture), args.runs)
            dm_part = median_ms(ctx, lambda: maps.run(texture, z0, z1), args.runs)
            start = time.perf_counter()
            reference.density_maps(density, maps.band_height, maps.group_size)
            dm_ref = (time.perf_counter() - start) * 1e3
            dm_tex = texture
        print(f"{f'smoothing r=1 tent, {layout}, {dtype}':34s} {whole:9.2f} {part:16.3f} "
              f"{THESIS_MS['smoothing']:10.3f} {ref:>9s}")
        smoother.release()
        if texture is not dm_tex:
            texture.release()
        if state is not ca:
            state.release()
    print(f"{f'density maps, {maps.bands} bands, {maps.grid[0]}x{maps.grid[1]}':34s} {dm_whole:9.2f} "
          f"{dm_part:16.3f} {THESIS_MS['density maps']:10.3f} {dm_ref:9.0f}")
    region_ms = region_volume_ms(gpu, shape, args.runs)
    for n, ms in region_ms.items():
        print(f"{f'region volume, {n} ellipsoids':34s} {ms:9.2f} {'':16s} {THESIS_MS['region volume']:10.3f}")
    maxes = maps.read_max_maps()
    print(f"max maps read back: {maxes.nbytes} bytes; segments to draw: {(maxes[0] > 0).sum()} of "
          f"{maxes[0].size} columns, {(maxes[1:] > 0).sum()} of {maxes[1:].size} band segments")
    print("thesis Table 8.1 (GeForce 8700M GT, pixel shaders, 256x32x256): volume smoothing "
          "6.024 ms, density map computation 0.588 ms, region volume 5.26 ms")
    plot(maps, density, args.out)
    print(f"wrote {args.out}")
    dm_tex.release()
    maps.release()
    ca.release()
    gpu.release()


if __name__ == "__main__":
    main()
