"""Host memory and pooled GL textures over 30 window resizes near 1280×720.

A cloud-free scene (sky, ground, fog, light shafts) renders a few frames at 1280×720, then at 30
sizes 1280+7k × 720+5k (k = 0..29, two frames each, as a user dragging a window edge), then a few
frames back at 1280×720. Prints host RSS (``/proc/self/statm``) and the textures and bytes the render
graph's pool holds at the start, at the peak and at the end, and the growth in %. Raw RSS keeps what
glibc's allocator holds on to after ``free`` (its mmap threshold rises after large frees), so RSS is
also shown after ``malloc_trim(0)`` ("trimmed"); on a software rasterizer atmos fixes glibc's mmap
threshold itself (:mod:`atmos.gpu.host_memory`), so raw RSS stays flat too. Goal: trimmed RSS and pool bytes end within 5 % of the start:
the pool evicts textures of sizes no frame uses any more (``TexturePool.end_frame``, ``keep_frames``).

    python benchmarks/bench_resize_memory.py [--sizes 30] [--frames-per-size 2] [--keep-frames 3]
    python benchmarks/bench_resize_memory.py --compare   # also the same run without eviction, in a subprocess
"""
from __future__ import annotations

import argparse
import ctypes
import os
import subprocess
import sys
import time

from atmos.app import App
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.plugins.fog import FogPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.light_shafts import LightShaftsPlugin
from atmos.plugins.sky import SkyPlugin

BASE = (1280, 720)
GOAL_PERCENT = 5.0
NO_EVICTION = 10 ** 9  # keep_frames that never evicts: the pool as it was before eviction


def rss_mb() -> float:
    """Resident set size of this process in MiB."""
    with open("/proc/self/statm") as f:
        resident = int(f.read().split()[1])
    return resident * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


def trimmed_rss_mb() -> float | None:
    """RSS after glibc's ``malloc_trim(0)`` hands freed heap pages back to the system (None off glibc).

    glibc raises its mmap threshold after a large block is freed, so later texture-sized blocks come
    from the heap and stay resident after ``free``: raw RSS then overstates what is still in use.
    """
    try:
        libc = ctypes.CDLL("libc.so.6")
        libc.malloc_trim(0)
    except (OSError, AttributeError):
        return None
    return rss_mb()


def snapshot(app, trim: bool = False) -> dict:
    pool = app.graph.pool
    shot = {"rss": rss_mb(), "textures": pool.textures, "bytes": pool.bytes / 2 ** 20,
            "framebuffers": app.graph._frame.cached_framebuffers}
    if trim:
        shot["trimmed"] = trimmed_rss_mb()
    return shot


def growth(start: float, end: float) -> float:
    return (end - start) / start * 100.0 if start else 0.0


def run(sizes: int, frames_per_size: int, keep_frames: int, rounds: int = 1) -> dict:
    gpu = create_headless(BASE)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyPlugin(), GroundPlugin(), FogPlugin(),
                               LightShaftsPlugin())
    app.graph.pool.keep_frames = keep_frames
    app.run_frames(keep_frames + 2 if keep_frames < NO_EVICTION else 5)
    passes = [p.name for p in app.graph.compile().order]
    start = snapshot(app, trim=True)
    peak = {key: value for key, value in start.items() if key != "trimmed"}
    t0 = time.perf_counter()
    round_ends = []
    for _ in range(rounds):
        for k in range(sizes):
            gpu.resize((BASE[0] + 7 * k, BASE[1] + 5 * k))
            app.run_frames(frames_per_size)
            now = snapshot(app)
            peak = {key: max(peak[key], now[key]) for key in peak}
        gpu.resize(BASE)
        app.run_frames(min(keep_frames, 8) + 1)
        round_ends.append(rss_mb())
    end = snapshot(app, trim=True)
    seconds = time.perf_counter() - t0
    evictions = app.graph.pool.evictions
    app.close()
    gpu.release()
    return {"start": start, "peak": peak, "end": end, "passes": passes, "seconds": seconds,
            "evictions": evictions, "keep_frames": keep_frames, "round_ends": round_ends}


def report(result: dict, label: str) -> bool:
    start, peak, end = result["start"], result["peak"], result["end"]
    print(f"\n{label} (keep_frames={result['keep_frames'] if result['keep_frames'] < NO_EVICTION else 'never'}; "
          f"passes: {', '.join(result['passes'])}; {result['seconds']:.1f} s)")
    print(f"  {'':14} {'start':>9} {'peak':>9} {'end':>9} {'growth':>8}")
    for key, unit in (("rss", "MiB"), ("bytes", "MiB"), ("textures", ""), ("framebuffers", "")):
        name = {"rss": "host RSS", "bytes": "pool bytes", "textures": "pool textures",
                "framebuffers": "framebuffers"}[key]
        print(f"  {name + (' ' + unit if unit else ''):14} {start[key]:9.1f} {peak[key]:9.1f} {end[key]:9.1f} "
              f"{growth(start[key], end[key]):+7.1f}%")
    if start.get("trimmed") is not None:
        print(f"  {'RSS trimmed':14} {start['trimmed']:9.1f} {'':>9} {end['trimmed']:9.1f} "
              f"{growth(start['trimmed'], end['trimmed']):+7.1f}%   (after malloc_trim(0): heap glibc kept)")
    if len(result["round_ends"]) > 1:
        print("  RSS MiB after each round of sizes: " + ", ".join(f"{r:.1f}" for r in result["round_ends"]))
    print(f"  pool evictions: {result['evictions']}")
    trimmed = start.get("trimmed") is not None
    rss_key = "trimmed" if trimmed else "rss"
    rss_ok = growth(start[rss_key], end[rss_key]) <= GOAL_PERCENT
    bytes_ok = growth(start["bytes"], end["bytes"]) <= GOAL_PERCENT
    print(f"  goal: {'trimmed ' if trimmed else ''}RSS and pool bytes grow <= {GOAL_PERCENT:g} % after the resizes: "
          f"{'met' if rss_ok and bytes_ok else 'MISSED'}")
    return rss_ok and bytes_ok


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, default=30)
    parser.add_argument("--frames-per-size", type=int, default=2)
    parser.add_argument("--keep-frames", type=int, default=3)
    parser.add_argument("--rounds", type=int, default=1, help="repeat the sweep of sizes (RSS should plateau)")
    parser.add_argument("--no-eviction", action="store_true", help="never evict (the pool before end_frame)")
    parser.add_argument("--compare", action="store_true", help="then run --no-eviction in a fresh process")
    args = parser.parse_args(argv)
    keep = NO_EVICTION if args.no_eviction else args.keep_frames
    print(f"resize memory: {args.sizes} sizes {BASE[0]}+7k x {BASE[1]}+5k, {args.frames_per_size} frames each")
    report(run(args.sizes, args.frames_per_size, keep, args.rounds), "without eviction" if args.no_eviction else "pool eviction")
    if args.compare and not args.no_eviction:
        sys.stdout.flush()
        subprocess.run([sys.executable, __file__, "--no-eviction", "--sizes", str(args.sizes),
                        "--frames-per-size", str(args.frames_per_size), "--rounds", str(args.rounds)], check=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
