"""Python per frame: function calls and CPU milliseconds a frame costs, without the GPU's time.

    python benchmarks/bench_python_frame.py [--frames 30] [--size 64x36] [--baseline REV_OR_DIR] [demo ...]

Scenes: ``sunset``, ``flight`` and any demo whose name contains "game" (or the demos named), headless
at a tiny frame size (64×36 by default: almost no fragment work) after 10 warm-up frames, at 1/30 s
per frame, so the simulation chain runs its slices as in the demo.

Method. *Calls*: ``sys.setprofile`` counts Python function calls (and C calls) over ``--frames``
frames. *Uniforms*: uniform values written per frame (``GLMeter.uniform_writes``; the rest of a
frame's constants are in uniform blocks). *Python ms*: frames timed in the main thread's CPU time (``time.thread_time``: waits,
llvmpipe's own threads and other processes do not count) with GL work stubbed out —
:class:`atmos.gpu.gl_meter.GLMeter` with ``stub_work=True`` turns every moderngl call that hands
the GPU work (draws, dispatches, clears, uploads) into a counted no-op, while state changes,
uniform writes, queries and readbacks still reach the driver — so it is the CPU cost of a frame as
if the GPU were infinitely fast: Python, moderngl's bindings and uniform writes included, llvmpipe
rasterizing and shading excluded (which also keeps it from flushing the CPU caches between
passes, as a real GPU would not). Readbacks' time and the meter's own cost per call (calibrated)
are subtracted. Cross-check, ``subtracted``: frames with the work done, minus the CPU time inside
the work calls. ``GL ms`` is that CPU time, ``wall ms`` the frame's wall time with the work done. ``--baseline`` runs the same measurement on another tree (a
git revision, extracted with ``git archive``, or a directory) in a subprocess, so before and after
come from one run on one machine.

Goals for sunset: <= 1 ms of Python per frame on the 2-core CI machine, <= 1,500 calls and <= 30
uniform writes per frame (tests/test_frame_budget.py holds the counts to a budget).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
GOAL_MS = 1.0
DEFAULT_SCENES = ("sunset", "flight")


def scenes(names=()) -> list[str]:
    """The demos to measure: ``names``, else sunset, flight and any demo named like a game."""
    if names:
        return list(names)
    from atmos.demo_registry import list_demos
    return list(DEFAULT_SCENES) + sorted(n for n in list_demos() if "game" in n and n not in DEFAULT_SCENES)


CLOCK = time.thread_time   # the main thread's CPU time: leaves out waits, llvmpipe's threads and other processes


def meter_overhead_s() -> float:
    """CPU seconds one GLMeter-wrapped call adds (a wrapped no-op against the bare one)."""
    from atmos.gpu.gl_meter import GLMeter

    class Probe:
        def noop(self):
            return None
    probe, n = Probe(), 20000
    bare = Probe.noop
    wrapped = GLMeter(clock=CLOCK)._wrap(bare, "Probe.noop", "work")
    best = []
    for func in (bare, wrapped):
        start = CLOCK()
        for _ in range(n):
            func(probe)
        best.append((CLOCK() - start) / n)
    return max(0.0, best[1] - best[0])


def measure(name: str, frames: int = 30, size=(64, 36), warmup: int = 10) -> dict:
    """Calls and milliseconds per frame of demo ``name`` (see the module docstring)."""
    from atmos.demo_registry import DemoSettings
    from atmos.gpu import create_headless
    from atmos.gpu.gl_meter import GLMeter, count_calls
    from atmos.runner import build_app

    gpu = create_headless(tuple(size))
    app = build_app(name, DemoSettings(size=tuple(size), headless=True), gpu)
    try:
        app.run_frames(warmup, 1 / 30)
        gpu.ctx.finish()
        python_calls, c_calls = count_calls(lambda: app.run_frames(frames, 1 / 30))
        gpu.ctx.finish()
        overhead = meter_overhead_s()
        subtracted, wall_ms, gl_ms, gl_calls, uniform_writes = [], [], [], [], []
        readbacks = Counter()
        with GLMeter(clock=CLOCK) as meter:          # the GPU's work done, and taken out of the time
            for _ in range(frames):
                gpu.ctx.finish()
                readbacks.update(f"{call} at {where}" for call, where in meter.readback_counts().elements()
                                 if not where.startswith("benchmarks/"))     # not the benchmark's own finish
                meter.reset()
                start, cpu = time.perf_counter(), CLOCK()
                app.update(1 / 30)
                wall, cpu = time.perf_counter() - start, CLOCK() - cpu
                wrapped = sum(meter.calls.values()) - meter.calls["Context.finish"]
                gl = meter.work_s + meter.readback_s
                wall_ms.append(wall * 1e3)
                gl_ms.append(gl * 1e3)
                gl_calls.append(wrapped)
                uniform_writes.append(meter.uniform_writes)
                subtracted.append((cpu - gl - wrapped * overhead) * 1e3)
            readbacks.update(f"{call} at {where}" for call, where in meter.readback_counts().elements()
                                 if not where.startswith("benchmarks/"))     # not the benchmark's own finish
        gpu.ctx.finish()
        stubbed = []
        with GLMeter(clock=CLOCK, stub_work=True) as meter:   # the GPU's work not done at all
            for _ in range(frames):
                meter.reset()
                cpu = CLOCK()
                app.update(1 / 30)
                cpu = CLOCK() - cpu
                wrapped = sum(meter.calls.values())
                stubbed.append((cpu - meter.readback_s - wrapped * overhead) * 1e3)
        return {"scene": name, "size": list(size), "frames": frames,
                "python_calls": python_calls / frames, "c_calls": c_calls / frames,
                "python_ms": float(np.mean(stubbed)), "python_ms_median": float(np.median(stubbed)),
                "python_ms_max": float(np.max(stubbed)), "python_ms_subtracted": float(np.mean(subtracted)),
                "wall_ms": float(np.mean(wall_ms)), "gl_ms": float(np.mean(gl_ms)),
                "gl_calls": float(np.mean(gl_calls)), "uniform_writes": float(np.mean(uniform_writes)),
                "readbacks_per_frame": {k: v / frames for k, v in sorted(readbacks.items())}}
    finally:
        app.close()
        gpu.release()


# -- the same measurement on another tree -------------------------------------------------------
_BOOTSTRAP = """
import importlib.util, json, sys
tree, here, args = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
sys.path.insert(0, here + "/benchmarks")
import tree_import
tree_import.install(tree)                       # atmos from the old tree ...
import atmos.gpu
spec = importlib.util.spec_from_file_location("atmos.gpu.gl_meter", here + "/atmos/gpu/gl_meter.py")
meter = sys.modules["atmos.gpu.gl_meter"] = importlib.util.module_from_spec(spec)
spec.loader.exec_module(meter)                  # ... measured with this tree's meter and benchmark
import bench_python_frame
print("RESULT " + json.dumps([bench_python_frame.measure(n, args["frames"], args["size"]) for n in args["scenes"]]))
"""


def baseline_tree(rev_or_dir: str, keep: list) -> str:
    """A directory holding the tree to compare against: ``rev_or_dir`` itself, or that git revision
    extracted with ``git archive`` into a temporary directory (kept alive through ``keep``)."""
    if os.path.isdir(rev_or_dir):
        return os.path.abspath(rev_or_dir)
    tmp = tempfile.TemporaryDirectory(prefix="atmos-baseline-")
    keep.append(tmp)
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev_or_dir], capture_output=True, check=False)
    if archive.returncode != 0:
        raise SystemExit(f"--baseline {rev_or_dir!r}: neither a directory nor a git revision "
                         f"({archive.stderr.decode().strip()})")
    subprocess.run(["tar", "-x", "-C", tmp.name], input=archive.stdout, check=True)
    return tmp.name


def measure_tree(tree: str, names, frames: int, size) -> list[dict]:
    """:func:`measure` of each scene on the atmos tree at ``tree``, in a fresh interpreter."""
    args = json.dumps({"scenes": list(names), "frames": frames, "size": list(size)})
    run = subprocess.run([sys.executable, "-c", _BOOTSTRAP, tree, str(ROOT), args], capture_output=True,
                         text=True, cwd=tree, env={**os.environ, "ATMOS_HEADLESS": "1"})
    line = next((ln for ln in run.stdout.splitlines() if ln.startswith("RESULT ")), None)
    if run.returncode != 0 or line is None:
        raise SystemExit(f"the baseline run on {tree} failed:\n{run.stderr[-3000:]}")
    return json.loads(line[len("RESULT "):])


def table(rows: list[dict], baseline: list[dict] | None = None) -> str:
    head = (f"{'scene':>8} {'tree':>8} | {'py calls':>8} {'C calls':>8} {'uniforms':>8} | {'python ms':>9} {'median':>7} "
            f"{'max':>7} {'subtracted':>10} | {'GL ms':>7} {'wall ms':>8} | goal")
    lines = [head, "-" * len(head)]
    old = {r["scene"]: r for r in baseline or []}
    for row in rows:
        for label, r in (("before", old.get(row["scene"])), ("now", row)):
            if r is None:
                continue
            goal = ""
            if r["scene"] == "sunset":
                goal = f"<= {GOAL_MS} ms: {'met' if r['python_ms'] <= GOAL_MS else 'MISSED'}"
            lines.append(f"{r['scene']:>8} {label:>8} | {r['python_calls']:8.0f} {r['c_calls']:8.0f} "
                         f"{r.get('uniform_writes', float('nan')):8.1f} | "
                         f"{r['python_ms']:9.3f} {r['python_ms_median']:7.3f} {r['python_ms_max']:7.3f} "
                         f"{r.get('python_ms_subtracted', float('nan')):10.3f} | "
                         f"{r['gl_ms']:7.2f} {r['wall_ms']:8.2f} | {goal}")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("demos", nargs="*", help="demos to measure (default: sunset, flight, games)")
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--size", default="64x36", help="frame size WxH (default 64x36)")
    parser.add_argument("--baseline", help="a git revision or a directory to measure beside this tree")
    parser.add_argument("--json", type=Path, help="write the rows as JSON here")
    args = parser.parse_args(argv)
    size = tuple(int(v) for v in args.size.lower().split("x"))
    names = scenes(args.demos)
    os.environ.setdefault("ATMOS_HEADLESS", "1")
    keep: list = []
    baseline = None
    if args.baseline:
        baseline = measure_tree(baseline_tree(args.baseline, keep), names, args.frames, size)
    rows = [measure(name, args.frames, size) for name in names]
    from atmos.gpu import create_headless
    gpu = create_headless((16, 16))
    renderer = gpu.info().get("GL_RENDERER")
    gpu.release()
    print(f"Python per frame, {size[0]}x{size[1]}, {args.frames} frames after 10 warm-up frames, {renderer}, "
          f"{os.cpu_count()} CPUs")
    print("python ms: main-thread CPU time per frame with GL work stubbed out (GLMeter stub_work); "
          "subtracted: with the work done, minus the CPU time inside the work calls")
    print(table(rows, baseline))
    for row in rows:
        print(f"{row['scene']}: GPU->CPU readbacks per frame")
        for where, n in row["readbacks_per_frame"].items():
            print(f"  {n:6.2f}  {where}")
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps({"now": rows, "before": baseline}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
