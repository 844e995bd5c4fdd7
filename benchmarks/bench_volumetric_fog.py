"""Volumetric fog: image error against a 1024-step march versus time per frame, 8..128 view steps per
pixel and froxel volumes of several sizes (VolumetricFogSettings.froxels), each frame alone
(froxel_history 1) and with the temporal history after the frames measured (the default); then the
noise (VolumetricFogSettings.noise): the FBM hashed per lattice corner and from the baked lattice,
filtered (one fetch per octave), per 2^20 points, and the demo's march and froxels with each.

Plain script: prints a table and writes out/bench_volumetric_fog.png. On llvmpipe only the ratios
between rows mean anything; absolute numbers need a real GPU.

    python benchmarks/bench_volumetric_fog.py [--size 320x180] [--frames 9]
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.froxels import HISTORY_BLEND
from atmos.demos.volumetric_fog import FOG
from atmos.gpu import create_headless
from atmos.graph import RenderPass
from atmos.lighting import Sun
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.volumetric_fog import VolumetricFogPlugin
from atmos.render_core import COLOR

STEPS = (8, 16, 32, 64, 128)
FROXELS = ((40, 23, 32), (80, 45, 32), (80, 45, 64), (160, 90, 64), (160, 90, 128), (256, 144, 64))
REFERENCE_STEPS = 1024


class ReadColor(RenderPass):
    """Reads the HDR colour back each frame (which also waits for the GPU to finish the frame)."""
    name = "read_color"
    phase = "readback"

    def setup(self, builder):
        builder.read(COLOR)
        builder.side_effect()

    def execute(self, frame):
        w, h = frame.gpu.size
        self.image = np.frombuffer(frame.resource(COLOR).read(), np.float16).reshape(h, w, 4)[..., :3].astype(float)


def fbm_ms(gpu, kind: str, octaves: int, repeats: int = 5, count: int = 1 << 20) -> float:
    """Median wall ms of volumetric_fog/fbm_points.comp over ``count`` points (the GPU waited for each
    time): the volumetric fog's FBM, ``kind`` "hash" or "filtered"."""
    from atmos.gpu.hazards import dispatch
    from atmos.gpu.uniforms import bind_buffers, bind_textures, write_uniforms
    from atmos.plugins.volumetric_fog import VolumetricFogSettings
    from atmos.plugins.volumetric_fog.noise import Lattice, noise_defines
    ctx = gpu.ctx
    lattice = None
    prog = gpu.program(compute_shader="volumetric_fog/fbm_points.comp",
                       defines=noise_defines(VolumetricFogSettings(noise=kind), gpu))
    if kind == "filtered":
        lattice = Lattice(gpu)
        bind_textures(prog, fog_lattice=lattice.sync(0))
    rng = np.random.default_rng(0)
    points = np.zeros((count, 4), np.float32)
    points[:, :3] = rng.uniform(-300.0, 300.0, (count, 3)) * 0.15
    src, dst = ctx.buffer(points.tobytes()), ctx.buffer(reserve=4 * count)
    bind_buffers(prog, Points=src, Values=dst)
    write_uniforms(prog, count=count, octaves=octaves, seed=0)
    times = []
    for _ in range(repeats + 1):
        ctx.finish()
        start = time.perf_counter()
        dispatch(prog, -(-count // 64))
        ctx.finish()
        times.append((time.perf_counter() - start) * 1000)
    src.release(), dst.release()
    if lattice is not None:
        lattice.release()
    return float(np.median(times[1:]))


def measure(app, plugin, reader, steps: int, frames: int, froxels=None, history: float = HISTORY_BLEND):
    """(image, median wall ms per frame, fog pass GPU ms) with ``steps`` view samples per pixel, or
    with a froxel volume of ``froxels`` (W, H, D) and ``froxel_history`` ``history`` (the image: the last
    frame's, a still view's history of frames + 2)."""
    plugin.configure(steps=steps, froxels=froxels, froxel_history=history)
    app.run_frames(2)                                       # warm up (and read the first timer queries)
    wall = []
    for _ in range(frames):
        start = time.perf_counter()
        app.update(1 / 60)
        wall.append((time.perf_counter() - start) * 1000)
    gpu_ms = app.graph.timings.get("volumetric_fog", (float("nan"),))[0]
    return (reader.image.copy() if reader else None), float(np.median(wall)), gpu_ms


def make_scene(gpu, read_color: bool = True):
    """(app, fog plugin, colour reader or None): sky gradient, ground and the demo's fog, seen from
    the demo's viewpoint with a low sun."""
    plugin = VolumetricFogPlugin(animate=False, **FOG)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(), plugin)
    app.insert_resource(Sun.from_angles(elevation_deg=18.0, azimuth_deg=120.0))
    cam = app.resource(Camera)
    cam.position = np.array([28.0, 14.0, 91.0])
    cam.look_at((0.0, 4.0, 0.0))
    reader = app.graph.add_pass(ReadColor()) if read_color else None
    app.graph.timings_enabled = True                        # the fog pass's timer query
    return app, plugin, reader


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="320x180")
    parser.add_argument("--frames", type=int, default=9)
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    gpu = create_headless(size)
    app, plugin, reader = make_scene(gpu)

    plugin.configure(noise="hash")         # the reference and the step and froxel rows: the hashed noise
    reference, ref_wall, ref_gpu = measure(app, plugin, reader, REFERENCE_STEPS, max(1, args.frames // 2))
    signal = np.sqrt(np.mean(reference ** 2))
    rows = []
    for steps in STEPS:
        image, wall, gpu_ms = measure(app, plugin, reader, steps, args.frames)
        rmse = float(np.sqrt(np.mean((image - reference) ** 2)))
        rows.append((steps, rmse, rmse / signal, wall, gpu_ms))
    rows.append((REFERENCE_STEPS, 0.0, 0.0, ref_wall, ref_gpu))
    froxel_rows = []
    for froxels in FROXELS:
        for history in (1.0, HISTORY_BLEND):
            image, wall, gpu_ms = measure(app, plugin, reader, 1, args.frames, froxels, history)
            rmse = float(np.sqrt(np.mean((image - reference) ** 2)))
            name = "x".join(map(str, froxels)) + (" history" if history < 1.0 else "")
            froxel_rows.append((name, rmse, rmse / signal, wall, gpu_ms))
    noise_rows = []                        # the demo's noise: the reference above is the exact noise's
    for kind in ("hash", "filtered"):
        plugin.configure(noise=kind)
        for steps, froxels in ((32, None), (1, FROXELS[-1])):
            image, wall, gpu_ms = measure(app, plugin, reader, steps, args.frames, froxels)
            rmse = float(np.sqrt(np.mean((image - reference) ** 2)))
            name = f"{kind} " + ("x".join(map(str, froxels)) if froxels else f"{steps} steps")
            noise_rows.append((name, rmse, rmse / signal, wall, gpu_ms))
    fbm_rows = [(kind, fbm_ms(gpu, kind, FOG["octaves"])) for kind in ("hash", "filtered")]
    info = gpu.info()
    app.close()
    gpu.release()

    print(f"volumetric fog, {size[0]}x{size[1]}, octaves {FOG['octaves']}, light steps 4, "
          f"renderer {info.get('GL_RENDERER', '?')}")
    print(f"{'steps':>6} {'RMSE':>10} {'rel. RMSE':>10} {'ms/frame':>10} {'fog GPU ms':>11}")
    for steps, rmse, rel, wall, gpu_ms in rows:
        print(f"{steps:>6} {rmse:>10.5f} {rel:>10.5f} {wall:>10.2f} {gpu_ms:>11.2f}")
    print(f"{'froxels':>19} {'RMSE':>10} {'rel. RMSE':>10} {'ms/frame':>10} {'fog GPU ms':>11}")
    for name, rmse, rel, wall, gpu_ms in froxel_rows:
        print(f"{name:>19} {rmse:>10.5f} {rel:>10.5f} {wall:>10.2f} {gpu_ms:>11.2f}")
    print(f"{'noise':>25} {'RMSE':>10} {'rel. RMSE':>10} {'ms/frame':>10} {'fog GPU ms':>11}")
    for name, rmse, rel, wall, gpu_ms in noise_rows:
        print(f"{name:>25} {rmse:>10.5f} {rel:>10.5f} {wall:>10.2f} {gpu_ms:>11.2f}")
    print(f"FBM of {FOG['octaves']} octaves at 2^20 points, ms: "
          + ", ".join(f"{kind} {ms:.2f}" for kind, ms in fbm_rows))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    xs = [r[3] for r in rows[:-1]]
    ax.loglog(xs, [r[1] for r in rows[:-1]], "o-", label="per pixel (steps)")
    for steps, rmse, _, wall, _ in rows[:-1]:
        ax.annotate(f"{steps}", (wall, rmse), textcoords="offset points", xytext=(5, 5))
    for kind, mark in (("", "s-"), (" history", "^-")):
        rows_of = [r for r in froxel_rows if r[0].endswith(" history") == bool(kind)]
        ax.loglog([r[3] for r in rows_of], [r[1] for r in rows_of], mark, label=f"froxels (W×H×D){kind}")
    for name, rmse, _, wall, _ in froxel_rows:
        ax.annotate(name.split()[0], (wall, rmse), textcoords="offset points", xytext=(5, -10), fontsize=7)
    ax.legend(fontsize=8)
    ax.set_xlabel("ms per frame (whole frame, wall clock)")
    ax.set_ylabel(f"image RMSE vs {REFERENCE_STEPS} steps (linear HDR)")
    ax.set_title(f"volumetric fog error vs run time ({size[0]}x{size[1]}, {info.get('GL_RENDERER', '?').split(' (')[0]})",
                 fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    os.makedirs("out", exist_ok=True)
    fig.tight_layout()
    fig.savefig("out/bench_volumetric_fog.png", dpi=100)
    print("wrote out/bench_volumetric_fog.png")


if __name__ == "__main__":
    main()
