"""Automaton step time at 256x32x256: packed GPU vs cell GPU vs the numpy reference.

A plain script (``python3 benchmarks/bench_automaton.py [--steps N] [--shape NX NY NZ]``) printing a
table of ms per step for (a) growth + advection and (b) a full step with stochastic rules driven by
per-cell float32 probability arrays. Per layout and case: the GPU's time per step (a timer query around
N queued steps), Python's (issuing them) and the wall clock (glFinish before and after), apart.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from split_timing import split_time

from atmos.gpu import create_headless
from atmos.plugins.clouds.automaton import CloudAutomaton, reference

THESIS_STEP_MS = 12.5   # Table 8.1, "Simulation step update", GeForce 8700M GT, 256x32x256


def initial_state(rng, shape):
    hum = rng.random(shape) < 0.35
    act = rng.random(shape) < 0.01
    cld = rng.random(shape) < 0.1
    return hum, act, cld


def time_gpu(gpu, layout, shape, state, kwargs, steps) -> dict:
    """{gpu_ms, python_ms, wall_ms} per step of ``steps`` queued steps (split_timing.split_time)."""
    ca = CloudAutomaton(gpu, shape, seed=1, layout=layout)
    ca.upload(*state)
    try:
        return split_time(gpu.ctx, lambda: ca.step(**kwargs), steps)    # the untimed first step packs the arrays
    finally:
        ca.release()


def time_numpy(shape, state, kwargs, steps):
    start = time.perf_counter()
    s = state
    for i in range(steps):
        s = reference.step(*s, seed=1, step=i, **kwargs)
    return (time.perf_counter() - start) * 1e3 / steps


GOALS = {"growth + advection": 15, "full step, per-cell p arrays": 5}   # packed speed-up over cell


def cases(shape, seed: int = 0):
    """(initial state, {case name: step keywords}) at ``shape``: growth + advection, and a full step
    with stochastic rules driven by per-cell float32 probability arrays."""
    rng = np.random.default_rng(seed)
    state = initial_state(rng, shape)
    ny = shape[1]
    shifts = np.stack([np.arange(ny) % 3, (np.arange(ny) // 8) % 2], axis=1).astype(np.int32)
    probs = {name: (rng.random(shape) * scale).astype(np.float32)
             for name, scale in (("p_ext", 0.1), ("p_hum", 0.1), ("p_act", 0.002))}
    return state, {"growth + advection": {"shift": shifts}, "full step, per-cell p arrays": {"shift": shifts, **probs}}


def measure(gpu, shape, steps: int, numpy_steps: int = 0) -> list[dict]:
    """One row per case: ms per step packed and cell (GPU, Python and wall, ``steps`` queued) and numpy
    (0: not run); the speed-up is the cell layout's GPU time over the packed one's (wall times where a
    driver runs compute while it is issued and the timer reads 0, as Mesa's llvmpipe does)."""
    state, kinds = cases(shape)
    rows = []
    for name, kwargs in kinds.items():
        packed = time_gpu(gpu, "packed", shape, state, kwargs, steps)
        cell = time_gpu(gpu, "cell", shape, state, kwargs, steps)
        ref = time_numpy(shape, state, kwargs, numpy_steps) if numpy_steps else None
        rows.append({"case": name, **{f"packed_{k}": v for k, v in packed.items()},
                     **{f"cell_{k}": v for k, v in cell.items()}, "numpy_ms": ref,
                     "speedup": (cell["gpu_ms"] / packed["gpu_ms"] if packed["gpu_ms"] > 0 and cell["gpu_ms"] > 0
                                 else cell["wall_ms"] / packed["wall_ms"]), "goal_speedup": GOALS[name],
                     "thesis_ms": THESIS_STEP_MS})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shape", type=int, nargs=3, default=(256, 32, 256))
    parser.add_argument("--steps", type=int, default=30, help="GPU steps timed per case and layout")
    parser.add_argument("--numpy-steps", type=int, default=2)
    args = parser.parse_args()
    shape = tuple(args.shape)
    gpu = create_headless((16, 16))
    ctx = gpu.ctx
    print(f"cloud automaton, {shape[0]}x{shape[1]}x{shape[2]} cells, {ctx.info['GL_RENDERER']}")
    head = (f"{'case':30s} {'packed GPU':>11s} {'Python':>8s} {'wall':>8s} {'cell GPU':>9s} {'Python':>8s} "
            f"{'wall':>8s} {'numpy':>8s} {'speed-up':>9s} {'goal':>5s}")
    print(head + "   (ms per step)")
    print("-" * len(head))
    for r in measure(gpu, shape, args.steps, args.numpy_steps):
        numpy_ms = f"{r['numpy_ms']:8.1f}" if r["numpy_ms"] is not None else f"{'-':>8s}"
        print(f"{r['case']:30s} {r['packed_gpu_ms']:11.3f} {r['packed_python_ms']:8.3f} {r['packed_wall_ms']:8.3f} "
              f"{r['cell_gpu_ms']:9.3f} {r['cell_python_ms']:8.3f} {r['cell_wall_ms']:8.3f} {numpy_ms} "
              f"{r['speedup']:8.1f}x {r['goal_speedup']:4d}x")
    print(f"thesis Table 8.1: simulation step update {THESIS_STEP_MS} ms on a GeForce 8700M GT "
          f"(256x32x256, pixel shader, one RGBA8 texel per cell, noise texture, region-volume control)")
    ctx.error
    gpu.release()


if __name__ == "__main__":
    main()
