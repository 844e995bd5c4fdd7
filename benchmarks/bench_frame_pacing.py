"""Frame pacing: a heavy simulation split into slices over frames vs. a whole step in one frame.

A synthetic heavy job (``tests/data/shaders/frames_heavy.comp``: a few hundred rounds of math per texel
over a 128×32×128 rgba16f volume, split into 32 slices of 4 z-layers) writes texture set C while a
light per-frame draw shows mix(A, B, t). Every frame ends with ``ctx.finish()`` so the frame time is
the real GPU time. Prints median, p99 and max frame time per mode, and writes the per-frame times to
``out/bench_frame_pacing.png``.

    python benchmarks/bench_frame_pacing.py [--frames 120] [--iterations 256] [--budget-ms 16]
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from atmos.slicing import FrameScheduler, SlicedJob, SliceTask, TripleSet
from atmos.gpu import add_shader_path, create_headless
from atmos.graph import TextureDesc
from atmos.gpu.uniforms import bind_images, bind_textures

VOLUME = (128, 32, 128)
SLICES = 32
ROOT = Path(__file__).resolve().parents[1]
add_shader_path(ROOT / "tests" / "data" / "shaders", prefix="test")   # the synthetic job the tests also run


def heavy_job(gpu, iterations: int) -> SlicedJob:
    triple = TripleSet(gpu, {"volume": TextureDesc(VOLUME, 4, "f2")})
    program = gpu.program(compute_shader="test/frames_heavy.comp")
    layers = VOLUME[2] // SLICES

    def begin(step):
        job.state["time"] = step * 0.1

    def run(index, job_ctx):
        bind_images(program, dst=job_ctx.target["volume"], src=job_ctx.previous["volume"])
        program["z0"] = index * layers
        program["iterations"] = iterations
        program["time"] = job_ctx.state["time"]
        program.run(VOLUME[0] // 8, VOLUME[1] // 8, layers)

    job = SlicedJob("heavy", [SliceTask("simulate", SLICES, run)], triple, begin=begin)
    return job


class Viewer:
    """The light per-frame draw: one horizontal slice of mix(A, B, t) over the frame."""

    def __init__(self, gpu):
        self.gpu = gpu
        self.program = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="test/frames_draw.frag")
        self.vao = gpu.track(gpu.ctx.vertex_array(self.program, []))

    def draw(self, job: SlicedJob) -> None:
        a, b, t = job.view()
        bind_textures(self.program, volume_a=a["volume"], volume_b=b["volume"])
        self.program["t"] = t
        self.program["layer"] = 0.5
        self.gpu.target.use()
        self.vao.render(vertices=3)


def run_mode(gpu, viewer, label: str, scheduler: FrameScheduler, frames: int, iterations: int):
    job = heavy_job(gpu, iterations)
    job.prime()
    scheduler.add(job)
    times, slices = [], []
    for frame in range(frames + 2):
        gpu.ctx.finish()
        start = time.perf_counter()
        scheduler.tick()
        viewer.draw(job)
        gpu.ctx.finish()
        if frame >= 2:  # two warm-up frames
            times.append((time.perf_counter() - start) * 1000.0)
            slices.append(scheduler.stats["heavy"].slices_last_frame)
    steps = job.step - 2
    scheduler.remove(job)
    job.release()
    return {"label": label, "times": np.array(times), "slices": np.array(slices), "steps": steps}


def summarize(result) -> dict:
    times = result["times"]
    return {"median": float(np.median(times)), "p99": float(np.percentile(times, 99)),
            "max": float(times.max()), "mean": float(times.mean()),
            "slices/frame": float(result["slices"].mean()), "steps": result["steps"]}


def plot(results, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 4.5), dpi=110)
    for result in results:
        ax.plot(np.arange(len(result["times"])), result["times"], label=result["label"], linewidth=1.2)
    ax.set_xlabel("frame")
    ax.set_ylabel("frame time (ms, with ctx.finish())")
    ax.set_yscale("log")
    ax.set_title(f"Frame pacing: {VOLUME[0]}×{VOLUME[1]}×{VOLUME[2]} heavy job, {SLICES} slices per step")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=120, help="measured frames per mode (default 120)")
    parser.add_argument("--iterations", type=int, default=256, help="math rounds per texel (default 256)")
    parser.add_argument("--budget-ms", type=float, default=16.0,
                        help="time budget of the third, budgeted mode in ms (0 leaves that mode out; default 16)")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "bench_frame_pacing.png")
    args = parser.parse_args(argv)

    os.environ.setdefault("ATMOS_HEADLESS", "1")
    gpu = create_headless((256, 144))
    info = gpu.info()
    viewer = Viewer(gpu)
    modes = [("sliced (1 slice/frame)", FrameScheduler("sliced", slices_per_frame=1)),
             ("naive (whole step/frame)", FrameScheduler("naive"))]
    if args.budget_ms > 0:
        modes.append((f"sliced ({args.budget_ms:g} ms budget)", FrameScheduler("sliced", time_budget_ms=args.budget_ms)))
    started = time.perf_counter()
    results = [run_mode(gpu, viewer, label, scheduler, args.frames, args.iterations) for label, scheduler in modes]
    elapsed = time.perf_counter() - started

    print(f"renderer: {info.get('GL_RENDERER')} | GL {info.get('GL_VERSION')}")
    print(f"job: {VOLUME[0]}x{VOLUME[1]}x{VOLUME[2]} rgba16f, {args.iterations} rounds/texel, {SLICES} slices/step; "
          f"{args.frames} frames per mode, ctx.finish() per frame; {elapsed:.1f} s")
    rows = [summarize(r) for r in results]
    width = max(len(r["label"]) for r in results)
    header = f"{'mode':<{width}}  {'median ms':>9}  {'p99 ms':>9}  {'max ms':>9}  {'mean ms':>9}  {'slices/fr':>9}  {'steps':>5}"
    print(header)
    print("-" * len(header))
    for result, row in zip(results, rows):
        print(f"{result['label']:<{width}}  {row['median']:>9.2f}  {row['p99']:>9.2f}  {row['max']:>9.2f}  "
              f"{row['mean']:>9.2f}  {row['slices/frame']:>9.2f}  {row['steps']:>5d}")
    print(f"max frame time naive / sliced: {rows[1]['max'] / rows[0]['max']:.1f}x")
    plot(results, args.out)
    print(f"plot: {args.out}")
    gpu.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())
