"""Every GPU benchmark of atmos in one command, for a machine with a real GPU.

    python benchmarks/gpu_suite.py [--quick] [--out DIR] [--only SECTION ...]

Sections (each reuses its benchmark module's functions, so the numbers are the same code's):

* ``automaton``  — ms per automaton step at 256×32×256, packed and cell (bench_automaton);
* ``tasks``      — smoothing, density maps, region volume (bench_cloud_tasks), beside Table 8.1;
* ``shading``    — shear-warp ×1/×2/×4 and the thesis fixed ratio vs the per-voxel ray march at
  256×32×256 (bench_shading), beside sec. 8.2;
* ``clouds``     — point-sprite clouds at 1920×1080, low / medium / high cover: no culling, frustum,
  frustum + empty-space skipping, 1/2 resolution, levels of detail (bench_cloud_render), beside
  Tables 8.2–8.4;
* ``fog``        — homogeneous and heterogeneous fog at 1920×1080 (bench_fog), beside the paper's 20 fps;
  ``volumetric fog`` at 32 and 64 steps per pixel and from froxel volumes (bench_volumetric_fog);
* ``pacing``     — the heavy sliced job: sliced vs naive frame times (bench_frame_pacing);
* ``sunset``     — the full sunset frame at 1920×1080 (its default clouds: the ray march): the render graph's per-pass GPU timer table
  (``app.graph.timings``), the simulation slices (timer queries), the whole frame in one timer
  query and by wall clock with glFinish, beside Nubis (≈ 2 ms per frame on a PS4); and Python per
  frame (bench_python_frame);
* ``raymarch``   — the sunset frame with each cloud renderer (sprites, the ray march of issue 15) at
  1024×768 and 1920×1080: frame ms, the cloud pass's GPU ms, the ratio (bench_cloud_raymarch).

Writes ``gpu_suite.md`` (one Markdown report, the thesis's and the anchors' figures beside ours)
and ``gpu_suite.json`` to ``--out`` (default ``out/``). ``--quick`` runs the same code at small
sizes (it is what tests/test_gpu_suite.py runs on llvmpipe); the sizes used are in the report.
Goals on an H100/H200: automaton step ≤ 10 µs GPU and ≤ 30 µs wall at 256×32×256, the sunset frame ≤ 2 ms GPU at
1920×1080. On llvmpipe only the ratios inside one run mean anything, and timer queries are not
GPU times.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))

GOALS = {"automaton_step_us": 10.0, "automaton_wall_us": 30.0, "sunset_frame_gpu_ms": 2.0}
ANCHORS = {"Nubis (Horizon Zero Dawn clouds), PS4": "≈ 2 ms per frame",
           "thesis GPU": "GeForce 8700M GT (32 shader units), 1024×768, 256×32×256 volume"}
SIZES = {   # full: what the thesis and the goals name; quick: the same code small enough for llvmpipe
    False: dict(volume=(256, 32, 256), frame=(1920, 1080), automaton_steps=200, repeats=7, render_frames=20,
                fog_frames=20, pacing_frames=120, pacing_iterations=256, sunset_frames=60, python_frames=30,
                raymarch_frames=((1024, 768), (1920, 1080)), raymarch_rounds=2),
    True: dict(volume=(64, 16, 64), frame=(160, 90), automaton_steps=3, repeats=1, render_frames=2,
               fog_frames=2, pacing_frames=6, pacing_iterations=8, sunset_frames=4, python_frames=3,
               raymarch_frames=((160, 90),), raymarch_rounds=1),
}
SECTIONS = ("automaton", "tasks", "shading", "clouds", "fog", "pacing", "sunset", "raymarch", "additions")


# -- sections: each returns {"title", "columns", "rows", "notes"} ------------------------------------
def automaton(cfg) -> dict:
    import bench_automaton
    from atmos.gpu import create_headless
    gpu = create_headless((16, 16))
    try:
        rows = bench_automaton.measure(gpu, cfg["volume"], cfg["automaton_steps"])
    finally:
        gpu.release()
    for r in rows:
        for layout in ("packed", "cell"):
            for part in ("gpu", "python", "wall"):
                r[f"{layout}_{part}_us"] = r[f"{layout}_{part}_ms"] * 1e3
    return {"title": f"Automaton step, {_shape(cfg['volume'])} cells ({cfg['automaton_steps']} queued steps: GPU by "
                     "timer query, Python issuing them, wall glFinish to glFinish)",
            "columns": [("case", "case"), ("packed GPU µs", "packed_gpu_us"), ("packed Python µs", "packed_python_us"),
                        ("packed wall µs", "packed_wall_us"), ("cell GPU µs", "cell_gpu_us"),
                        ("cell Python µs", "cell_python_us"), ("cell / packed (GPU)", "speedup"),
                        ("thesis ms (Table 8.1)", "thesis_ms")],
            "rows": rows,
            "notes": [f"goal on an H100/H200: packed full step ≤ {GOALS['automaton_step_us']:g} µs GPU and ≤ {GOALS['automaton_wall_us']:g} µs wall at 256×32×256",
                      "a GPU time of 0: the driver ran the steps while they were issued (Mesa's llvmpipe), the Python column holds them",
                      "thesis: 12.5 ms per simulation step update, GeForce 8700M GT, pixel shader, one RGBA8 texel per cell"]}


def tasks(cfg) -> dict:
    import bench_cloud_tasks
    from atmos.gpu import create_headless
    gpu = create_headless((16, 16))
    try:
        rows = bench_cloud_tasks.measure(gpu, cfg["volume"], cfg["repeats"], 32 if cfg["volume"][2] >= 32 else 4,
                                         references=False)
    finally:
        gpu.release()
    return {"title": f"Simulation tasks, {_shape(cfg['volume'])} cells (median, glFinish around each)",
            "columns": [("stage", "stage"), ("whole ms", "whole_ms"), ("one slice ms", "slice_ms"),
                        ("thesis ms (Table 8.1)", "thesis_ms")],
            "rows": [r for r in rows if r["whole_ms"] is not None],
            "notes": ["thesis Table 8.1: region volume 5.263 ms, simulation step 12.5 ms, smoothing 6.024 ms, "
                      "density maps 0.588 ms (all four ≈ 45 steps per second)"]}


def shading(cfg) -> dict:
    import numpy as np
    import bench_shading
    from atmos.gpu import create_headless
    gpu = create_headless((16, 16))
    try:
        density = bench_shading.smooth_volume(cfg["volume"], np.random.default_rng(1))
        results = bench_shading.run_methods(gpu, density, bench_shading.sun_direction(30), cfg["repeats"])
    finally:
        gpu.release()
    march = results["raymarch"][0]
    thesis = {"shear-warp x1": bench_shading.THESIS_MS, "shear-warp x2": 1000.0 / 460, "thesis fixed-ratio": bench_shading.THESIS_MS}
    rows = [{"method": m, "ms": ms, "x_march": march / ms, "thesis_ms": thesis.get(m)} for m, (ms, _) in results.items()]
    return {"title": f"Shading, {_shape(cfg['volume'])} voxels, sun at 30° (a full pass, median)",
            "columns": [("method", "method"), ("ms", "ms"), ("ray march / this", "x_march"),
                        ("thesis ms (sec. 8.2)", "thesis_ms")],
            "rows": rows,
            "notes": ["thesis sec. 8.2: 8.696 ms at full resolution, 460 per second at half (GeForce 8700M GT)"]}


def clouds(cfg) -> dict:
    import bench_cloud_render
    from atmos.gpu import create_headless
    gpu = create_headless(cfg["frame"])
    try:
        rows = bench_cloud_render.culling_rows(gpu, cfg["volume"], cfg["render_frames"])
    finally:
        gpu.release()
    return {"title": f"Cloud rendering, {_shape(cfg['volume'])} cells at {_shape(cfg['frame'])} "
                     "(render graph: sky, ground, clouds; median frame, glFinish; ms: blended points, splat ms: splatted in compute)",
            "columns": [("cover", "cover"), ("measured cover", "actual_cover"), ("config", "config"), ("ms", "ms"),
                        ("fps", "fps"), ("splat ms", "splat_ms"), ("points / splat", "x_splat"),
                        ("sprites", "sprites"), ("× none", "x_none"),
                        ("thesis fps (Tables 8.2–8.4)", "thesis_fps"), ("thesis ×", "thesis_x")],
            "rows": rows,
            "notes": ["thesis at 1024×768 on a GeForce 8700M GT: low 33 / 95 / 118 fps, medium 25 / 51 / 55, "
                      "high 11 / 21 / 33 (none / frustum / frustum + ESS)"]}


def fog(cfg) -> dict:
    import bench_fog
    import bench_volumetric_fog
    from bench_cloud_render import render_ms
    from atmos.gpu import create_headless
    gpu = create_headless(cfg["frame"])
    rows = []
    try:
        for label, fields in (("homogeneous exp2 (eq. 4)", {"mode": "exp2"}),
                              ("heterogeneous, texture noise, 4 octaves", {"noise": "texture", "octaves": 4}),
                              ("heterogeneous, procedural noise, 4 octaves", {"noise": "procedural", "octaves": 4})):
            _, pass_ms, frame_ms = bench_fog.render(gpu, cfg["frame"], cfg["fog_frames"], **fields)
            rows.append({"effect": label, "pass_gpu_ms": pass_ms, "frame_ms": frame_ms})
        app, plugin, _ = bench_volumetric_fog.make_scene(gpu, read_color=False)
        try:
            for label, fields in [(f"volumetric fog, {steps} steps per pixel", dict(steps=steps, froxels=None))
                                  for steps in (32, 64)] + \
                                 [(f"volumetric fog, froxels {'x'.join(map(str, size))}", dict(froxels=size))
                                  for size in ((160, 90, 64), (256, 144, 64))]:      # the demo's: 256x144x64
                plugin.configure(**fields)
                frame_ms = render_ms(app, cfg["fog_frames"])
                rows.append({"effect": label, "frame_ms": frame_ms,
                             "pass_gpu_ms": app.graph.timings.get("volumetric_fog", (float("nan"),))[0]})
        finally:
            app.close()
    finally:
        gpu.release()
    return {"title": f"Fog at {_shape(cfg['frame'])} (fog_valley scene; volumetric fog demo view)",
            "columns": [("effect", "effect"), ("fog pass GPU ms (timer query)", "pass_gpu_ms"),
                        ("frame ms (glFinish)", "frame_ms")],
            "rows": rows,
            "notes": [f"paper: {bench_fog.PAPER[1]:.0f} ms per frame (20 fps), {bench_fog.PAPER[0]}"]}


def pacing(cfg) -> dict:
    import bench_frame_pacing
    from atmos.slicing import FrameScheduler
    from atmos.gpu import create_headless
    gpu = create_headless((256, 144))
    rows = []
    try:
        viewer = bench_frame_pacing.Viewer(gpu)
        for label, scheduler in (("sliced (1 slice/frame)", FrameScheduler("sliced", slices_per_frame=1)),
                                 ("naive (whole step/frame)", FrameScheduler("naive"))):
            result = bench_frame_pacing.run_mode(gpu, viewer, label, scheduler, cfg["pacing_frames"],
                                                 cfg["pacing_iterations"])
            rows.append({"mode": label, **bench_frame_pacing.summarize(result)})
    finally:
        gpu.release()
    return {"title": f"Frame pacing: a heavy job ({_shape(bench_frame_pacing.VOLUME)}, {cfg['pacing_iterations']} "
                     f"rounds/texel, {bench_frame_pacing.SLICES} slices), {cfg['pacing_frames']} frames, glFinish per frame",
            "columns": [("mode", "mode"), ("median ms", "median"), ("p99 ms", "p99"), ("max ms", "max"),
                        ("slices/frame", "slices/frame"), ("steps", "steps")],
            "rows": rows,
            "notes": ["thesis 8.1.2: one slice of 32 per frame did not affect the frame rate"]}


def sunset(cfg) -> dict:
    import bench_python_frame
    from atmos.demo_registry import DemoSettings
    from atmos.slicing import timer_query_measure
    from atmos.gpu import create_headless
    from atmos.graph.timing import RING
    from atmos.runner import build_app
    gpu = create_headless(cfg["frame"])
    ctx = gpu.ctx
    frames = cfg["sunset_frames"]
    try:
        app = build_app("sunset", DemoSettings(size=cfg["frame"], headless=True), gpu)
        try:
            app.frames.measure = timer_query_measure(ctx, late=False)  # each slice's GPU time (read at once)
            app.graph.timings_enabled = True
            app.run_frames(RING + 1, 1 / 30)
            per_pass: dict[str, list] = {}
            slices, slice_ms, wall = [], [], []
            for _ in range(frames):
                ctx.finish()
                start = time.perf_counter()
                app.update(1 / 30)
                ctx.finish()
                wall.append((time.perf_counter() - start) * 1e3)
                slices.append(app.frames.slices_last_frame)
                slice_ms.append(app.frames.ms_last_frame)
                for name, (gpu_ms, cpu_ms) in app.graph.timings.items():
                    per_pass.setdefault(name, []).append((gpu_ms, cpu_ms))
            order = [p.name for p in app.graph.compile().order if p.name in per_pass]
            rows = [{"part": f"pass {name}", "gpu_ms": statistics.median(g for g, _ in per_pass[name]),
                     "cpu_ms": statistics.median(c for _, c in per_pass[name])} for name in order]
            rows.append({"part": f"simulation slices ({statistics.mean(slices):.1f} per frame)",
                         "gpu_ms": statistics.median(slice_ms), "cpu_ms": None})
            rows.append({"part": "sum of the above", "gpu_ms": sum(r["gpu_ms"] for r in rows), "cpu_ms": None})
            # the whole frame in one timer query: per-pass queries off (time queries cannot nest)
            app.graph.timings_enabled = False
            app.frames.measure = None
            query = ctx.query(time=True)
            whole = []
            for _ in range(frames):
                ctx.finish()
                with query:
                    app.update(1 / 30)
                ctx.finish()
                whole.append(query.elapsed / 1e6)
            rows.append({"part": "whole frame (one timer query)", "gpu_ms": statistics.median(whole), "cpu_ms": None,
                         "goal": f"≤ {GOALS['sunset_frame_gpu_ms']:g} ms on an H100/H200",
                         "anchor": ANCHORS["Nubis (Horizon Zero Dawn clouds), PS4"]})
            rows.append({"part": "whole frame, wall clock with glFinish", "gpu_ms": statistics.median(wall),
                         "cpu_ms": None})
        finally:
            app.close()
    finally:
        gpu.release()
    python = bench_python_frame.measure("sunset", cfg["python_frames"])
    rows.append({"part": "Python per frame (bench_python_frame, 64×36)", "gpu_ms": None,
                 "cpu_ms": python["python_ms"], "goal": "≤ 1 ms on the CI machine"})
    return {"title": f"The sunset frame at {_shape(cfg['frame'])} (median of {frames} frames)",
            "columns": [("part", "part"), ("GPU ms", "gpu_ms"), ("CPU ms", "cpu_ms"), ("goal", "goal"),
                        ("anchor", "anchor")],
            "rows": rows,
            "notes": ["per-pass GPU times come from the render graph's timer queries (each read once its result is in, without waiting); "
                      "the slices from one timer query each; CPU ms of a pass is its execute() wall time"]}


def raymarch(cfg) -> dict:
    import bench_cloud_raymarch
    rows = []
    for size in cfg["raymarch_frames"]:
        for row in bench_cloud_raymarch.sunset_rows(size, cfg["raymarch_rounds"], cfg["sunset_frames"]):
            rows.append({"frame": _shape(size), **row})
    return {"title": "The sunset frame with each cloud renderer: point sprites vs the ray march (issue 15), "
                     "alternated in one App",
            "columns": [("frame", "frame"), ("renderer", "renderer"), ("frame ms (glFinish)", "frame_ms"),
                        ("× sprites", "x_sprites_frame"), ("cloud pass", "pass"), ("pass GPU ms (timer query)", "pass_gpu_ms"),
                        ("pass × sprites", "x_sprites_pass"), ("settings", "settings")],
            "rows": rows,
            "notes": ["bench_cloud_raymarch.sunset_rows; the march at its defaults (resolution 2 with reprojection)",
                      "anchor: Nubis ≈ 2 ms per frame on a PS4, 1/16 of the pixels marched per frame"]}


def _pass_ms(app, names, frames: int) -> dict:
    """Median GPU ms of the passes ``names`` over ``frames`` frames (after the timer ring fills)."""
    from atmos.graph.timing import RING
    app.run_frames(RING + 1, 1 / 30)
    seen = {name: [] for name in names}
    for _ in range(frames):
        app.update(1 / 30)
        for name in names:
            timing = app.graph.timings.get(name)
            if timing:
                seen[name].append(timing[0])
    return {name: statistics.median(v) if v else float("nan") for name, v in seen.items()}


def additions(cfg) -> dict:
    """What two additions cost a frame on the GPU, each beside what it replaced in one App: the temporal
    AA following moving meshes by their own motion (glider) and the ray march's cloud types by region
    with towers (flight with the march)."""
    from atmos.demo_registry import DemoSettings
    from atmos.gpu import create_headless
    from atmos.plugins.antialias import AntialiasPlugin
    from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
    from atmos.runner import build_app
    rows = []
    cases = (("glider", None, AntialiasPlugin, ("meshes", "temporal_aa"),
              (("meshes' motion target", {}), ("camera motion only", {"motion": False}))),
             ("flight", "march", RaymarchCloudsPlugin, ("cloud_raymarch",),
              (("types by region, towers", {}), ("one type (cumulus)", {"type_map": None}))))
    for demo, renderer, kind, names, variants in cases:
        gpu = create_headless(cfg["frame"])
        try:
            settings = DemoSettings(size=cfg["frame"], headless=True, **({"clouds": renderer} if renderer else {}))
            app = build_app(demo, settings, gpu)
            try:
                plugin = next(p for p in app.plugins if isinstance(p, kind))
                own = plugin.settings
                app.graph.timings_enabled = True
                touched = {name for _, changes in variants for name in changes}
                for label, changes in variants:        # each from the demo's own settings
                    plugin.configure(**{**{name: getattr(own, name) for name in touched}, **changes})
                    for name, ms in _pass_ms(app, names, cfg["render_frames"]).items():
                        rows.append({"demo": demo, "variant": label, "pass": name, "gpu_ms": ms})
            finally:
                app.close()
        finally:
            gpu.release()
    return {"title": f"Additions at {_shape(cfg['frame'])}: the TAA's motion target, cloud types by region",
            "columns": [("demo", "demo"), ("variant", "variant"), ("pass", "pass"), ("GPU ms (timer query)", "gpu_ms")],
            "rows": rows,
            "notes": ["the meshes draw the motion target only while the TAA follows it; the march's box rises to "
                      "the towers' top where a type passes cumulus (shape.march_top)"]}


RUNNERS = {"automaton": automaton, "tasks": tasks, "shading": shading, "clouds": clouds, "fog": fog,
           "pacing": pacing, "sunset": sunset, "raymarch": raymarch, "additions": additions}


# -- the report --------------------------------------------------------------------------------------
def _shape(values) -> str:
    return "×".join(str(v) for v in values)


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        if value != value:
            return "n/a"
        return f"{value:.3g}" if abs(value) < 1000 else f"{value:.0f}"
    return str(value)


def markdown(report: dict) -> str:
    m = report["machine"]
    lines = [f"# atmos GPU suite{' (--quick: small sizes, not the thesis setup)' if report['quick'] else ''}", "",
             f"- renderer: {m['renderer']} ({m['vendor']}), OpenGL {m['gl_version']}",
             f"- CPU: {m['cpu']} ({m['cpus']} logical), Python {m['python']}, {m['platform']}",
             f"- sizes: volume {_shape(report['sizes']['volume'])}, frame {_shape(report['sizes']['frame'])}; "
             f"total {report['seconds']:.0f} s",
             f"- goals (H100/H200): automaton step ≤ {GOALS['automaton_step_us']:g} µs GPU, ≤ {GOALS['automaton_wall_us']:g} µs wall at 256×32×256; "
             f"sunset frame ≤ {GOALS['sunset_frame_gpu_ms']:g} ms GPU at 1920×1080",
             *[f"- anchor: {k}: {v}" for k, v in ANCHORS.items()], ""]
    for name, section in report["sections"].items():
        lines += [f"## {name}: {section['title']}", ""]
        if "error" in section:
            lines += [f"**failed**: `{section['error']}`", ""]
            continue
        heads = [h for h, _ in section["columns"]]
        lines += ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
        for row in section["rows"]:
            lines.append("| " + " | ".join(_cell(row.get(key)) for _, key in section["columns"]) + " |")
        lines += [""] + [f"- {note}" for note in section["notes"]] + [f"- {section['seconds']:.1f} s", ""]
    return "\n".join(lines)


def machine() -> dict:
    from atmos.gpu import create_headless
    gpu = create_headless((16, 16))
    info = gpu.info()
    gpu.release()
    cpu = platform.processor() or platform.machine()
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return {"renderer": info.get("GL_RENDERER"), "vendor": info.get("GL_VENDOR"), "gl_version": info.get("GL_VERSION"),
            "cpu": cpu, "cpus": os.cpu_count(), "python": platform.python_version(), "platform": platform.platform()}


def run(quick: bool, only=SECTIONS) -> dict:
    """Run the sections in ``only``; a section that fails is reported with its error, the rest still run."""
    cfg = SIZES[quick]
    started = time.perf_counter()
    report = {"quick": quick, "sizes": cfg, "machine": machine(), "goals": GOALS, "anchors": ANCHORS, "sections": {}}
    for name in only:
        t = time.perf_counter()
        print(f"[gpu_suite] {name} ...", file=sys.stderr, flush=True)
        try:
            section = RUNNERS[name](cfg)
        except Exception as error:          # keep the other sections' numbers
            section = {"title": name, "error": f"{type(error).__name__}: {error}"}
        section["seconds"] = time.perf_counter() - t
        report["sections"][name] = section
        print(f"[gpu_suite] {name}: {section['seconds']:.1f} s", file=sys.stderr, flush=True)
    report["seconds"] = time.perf_counter() - started
    return report


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the same code at small sizes (llvmpipe)")
    parser.add_argument("--out", type=Path, default=ROOT / "out", help="folder for gpu_suite.md and gpu_suite.json")
    parser.add_argument("--only", nargs="+", choices=SECTIONS, default=list(SECTIONS), metavar="SECTION",
                        help=f"run only these sections ({', '.join(SECTIONS)})")
    args = parser.parse_args(argv)
    os.environ.setdefault("ATMOS_HEADLESS", "1")
    report = run(args.quick, args.only)
    args.out.mkdir(parents=True, exist_ok=True)
    text = markdown(report)
    (args.out / "gpu_suite.md").write_text(text)
    (args.out / "gpu_suite.json").write_text(json.dumps(report, indent=1, default=str))
    print(text)
    print(f"wrote {args.out / 'gpu_suite.md'} and {args.out / 'gpu_suite.json'}", file=sys.stderr)
    failed = [name for name, s in report["sections"].items() if "error" in s]
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
