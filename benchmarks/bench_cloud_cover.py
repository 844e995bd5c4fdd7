"""Cloud cover over time: nearly constant under fixed weather, moved at the adaption pace.

A plain script (``python3 benchmarks/bench_cloud_cover.py``): runs the whole cloud chain (weather
→ region → automaton → smoothing → density maps) on a 64×8×64 volume for 1000 steps with fixed
parameters, then raises the cloud density, then lowers it, for two adaption paces; prints the
cover band after warm-up and the steps each change took, and writes ``out/bench_cloud_cover.png``.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from atmos.app import App
from atmos.gpu import create_headless
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.clouds.weather import Ellipsoid, WeatherSettings

OUT = Path(__file__).resolve().parents[1] / "out" / "bench_cloud_cover.png"
SCHEDULE = [(0, 80), (1000, 160), (1300, 40)]      # (step, cloud_density)
STEPS = 1600


def run(gpu, adaption: int):
    params = WeatherSettings(volume_shape=(64, 8, 64), cloud_density=SCHEDULE[0][1], density_adaption=adaption,
                           cloud_size=4.0, cloud_size_variance=1.5, region_margin=6.0, lifetime=400.0,
                           lifetime_variance=50.0, hum_scale=0.2, act_scale=0.01, ext_scale=0.1,
                           vertical_scale=0.5, altitude_variance=0.1, wind=(0.5, 0.0, 0.25))
    app = App(gpu)
    plugin = CloudsPlugin(CloudSettings(weather=params, smoothing_slices=2, group_size=(16, 16)), seed=7)
    app.add_plugins(plugin)
    app.startup()
    sim = plugin.simulation
    targets = dict(SCHEDULE)
    cover, count = [], []
    start = time.perf_counter()
    for step in range(STEPS):
        if step in targets:
            params.cloud_density = targets[step]
        sim.job.run_step()
        cover.append(sim.cover())
        count.append(len(app.world.get_component(Ellipsoid)))
    ms = (time.perf_counter() - start) * 1e3 / STEPS
    app.close()
    return np.array(cover), np.array(count), ms


def settle_steps(cover, begin: int, end: int) -> int:
    """Steps after ``begin`` until the cover first comes within 10 % of its level over [end-100, end)."""
    level = cover[end - 100:end].mean()
    before = cover[begin - 50:begin].mean()
    within = np.abs(cover[begin:end] - level) <= 0.1 * abs(level - before) + 0.01
    return int(np.argmax(within))


def main() -> None:
    gpu = create_headless((16, 16))
    runs = {adaption: run(gpu, adaption) for adaption in (2, 8)}
    print(f"cloud cover, 64x8x64 cells, {STEPS} steps, {gpu.ctx.info['GL_RENDERER']}")
    print(f"{'adaption':>8s} {'band (steps 200-1000)':>28s} {'std':>6s} {'->160 steps':>12s} "
          f"{'->40 steps':>11s} {'ms/step':>8s}")
    for adaption, (cover, count, ms) in runs.items():
        band = cover[200:1000]
        print(f"{adaption:8d} {f'{band.mean():.3f} [{band.min():.3f}, {band.max():.3f}]':>28s} {band.std():6.3f} "
              f"{settle_steps(cover, 1000, 1300):12d} {settle_steps(cover, 1300, STEPS):11d} {ms:8.2f}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for adaption, (cover, count, _) in runs.items():
        top.plot(cover, lw=0.8, label=f"adaption {adaption}/step")
        bottom.plot(count, lw=0.8, label=f"adaption {adaption}/step")
    for step, density in SCHEDULE:
        bottom.axhline(density, color="grey", lw=0.5, ls=":")
        top.axvline(step, color="grey", lw=0.5, ls=":")
    top.set_ylabel("cloud cover (fraction of columns)")
    bottom.set_ylabel("ellipsoids")
    bottom.set_xlabel("simulation step")
    top.legend()
    top.set_title("cover under fixed weather, then cloud density 80 → 160 → 40")
    OUT.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(OUT, dpi=110)
    print(f"wrote {OUT}")
    gpu.release()


if __name__ == "__main__":
    main()
