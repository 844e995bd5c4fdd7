"""The diffusion field's CG solve (plugins/clouds/light/diffusion.py): error vs iterations vs time, cold and warm.

A plain script (``python benchmarks/bench_cloud_field.py [--demo sunset] [--runs 3]``): runs the demo's
cloud chain until two texture sets hold clouds, then solves set B's field on the GPU with a cap of
10..300 CG iterations, started cold (phi = 0) and warm (from set A's converged field, what the cloud
chain does every step), and prints per cap: the relative residual |b - A phi| / |b|, phi's relative
RMSE against the float64 solve (tolerance 1e-10), and the GPU ms (ctx.finish() before and after,
median of ``--runs``). Converged iterations are indirect dispatches of 0 groups (0.13 ms each on
llvmpipe, next to nothing on a GPU); the caps (``ITERATIONS`` cold, ``WARM_ITERATIONS`` warm) must lie
past convergence in this table. Writes ``out/bench_cloud_field.png``.
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.plugins.clouds import CloudSimulation, read_volume
from atmos.runner import build_app
from atmos.plugins.clouds.light.diffusion import (DIFFUSION, ITERATIONS, WARM_ITERATIONS, diffusion_reference, field_medium,
                                     read_field, resample)

ROOT = Path(__file__).resolve().parents[1]
CAPS = (10, 25, 50, 75, 100, 150, 200, 300)


def read_transmittance(texture) -> np.ndarray:
    nx, ny, nz = texture.size
    return np.frombuffer(texture.read(), np.float16).reshape(nz, ny, nx).transpose(2, 1, 0).astype(np.float64)


def solve_ms(gpu, solver, texture_set, medium, cap: int, warm_from=None) -> float:
    """GPU ms of one solve of ``texture_set``'s field with ``cap`` iterations, cold or warm from the
    converged field of ``warm_from`` (solved first, untimed)."""
    if warm_from is not None:
        solver.solve(warm_from["density"], warm_from["transmittance"], warm_from[DIFFUSION], *medium,
                     iterations=ITERATIONS, warm=False)
    gpu.ctx.finish()
    start = time.perf_counter()
    solver.solve(texture_set["density"], texture_set["transmittance"], texture_set[DIFFUSION], *medium,
                 iterations=cap, warm=warm_from is not None)
    gpu.ctx.finish()
    return (time.perf_counter() - start) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--demo", default="sunset", help="a cloud demo whose volume is solved (default sunset)")
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    gpu = create_headless((64, 36))
    app = build_app(args.demo, DemoSettings(size=gpu.size, headless=True), gpu)
    app.run_frames(1, 1 / 30)
    sim = app.resource(CloudSimulation)
    sim.job.run_step()
    sim.job.run_step()                     # A and B both solved with the renderer's demand
    a, b, _ = sim.view()
    solver = sim.field.solver
    medium = field_medium(sim.settings, sim.sun())
    shape = solver.field_shape
    cell = np.asarray(sim.settings.cell_size, np.float64) * np.array(sim.shape) / np.array(shape)
    density = resample(read_volume(b["density"]), shape)
    T = resample(read_transmittance(b["transmittance"]), shape)
    ref = diffusion_reference(density, cell, *medium[:3], T, medium[4])[..., 0]
    scale = np.sqrt((ref ** 2).mean())
    print(f"{args.demo}: volume {sim.shape}, field grid {shape} ({solver.cells} cells); "
          f"caps: cold {ITERATIONS}, warm {WARM_ITERATIONS}")
    print(f"{'start':>5} {'cap':>4} {'residual':>9} {'phi rel RMSE':>12} {'ms':>8}")
    rows = []
    for start in ("cold", "warm"):
        for cap in CAPS:
            times = [solve_ms(gpu, solver, b, medium, cap, a if start == "warm" else None) for _ in range(args.runs)]
            residual = solver.relative_residual()
            err = np.sqrt(((read_field(b[DIFFUSION])[..., 0] - ref) ** 2).mean()) / scale
            rows.append((start, cap, residual, err, statistics.median(times)))
            print(f"{start:>5} {cap:>4} {residual:9.2e} {err:12.2e} {statistics.median(times):8.1f}")
    app.close()
    gpu.release()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    for start, marker in (("cold", "o"), ("warm", "s")):
        pick = [r for r in rows if r[0] == start]
        left.semilogy([r[1] for r in pick], [r[3] for r in pick], marker=marker, label=start)
        right.semilogy([r[4] for r in pick], [r[3] for r in pick], marker=marker, label=start)
    left.set_xlabel("CG iterations (cap)")
    right.set_xlabel("GPU ms (llvmpipe unless on a GPU)")
    for ax in (left, right):
        ax.set_ylabel("phi relative RMSE vs float64")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle(f"diffusion field, {args.demo}: error vs iterations and time")
    fig.tight_layout()
    out = ROOT / "out" / "bench_cloud_field.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
