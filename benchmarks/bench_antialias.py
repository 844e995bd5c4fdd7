"""Anti-aliasing: each mode's image against a 4x4 supersampled frame of the same view (relative RMSE as
displayed), still, while the camera turns and while the box slides, with the pass's GPU ms beside (one
run, this machine).

A box over the ground plane under a gradient sky (the edges of a mesh, the horizon, the plane's
checkerboard into the distance), 320x180, modes: none, FXAA, TAA (AntialiasSettings.mode "taa",
history 0.1) and TAA without the meshes' motion (``motion=False``: reprojected by the camera alone).
Still: 24 frames, the last compared. Turning 0.5 degrees a frame, the box sliding 2 cm a frame (about
half a pixel) past a still camera, or the camera chasing the box sliding 20 cm a frame (a game's chase
camera: the box still on screen, the world sweeping past): 24 frames, the mean over the last 12 (TAA's
ghosting or blur would show there).

    .venv/bin/python benchmarks/bench_antialias.py
"""
from __future__ import annotations

import math

import numpy as np

from atmos import App, DefaultPlugins, MeshInstance, MeshPlugin, Transform, box
from atmos.camera import Camera
from atmos.gpu import create_headless
from atmos.plugins.antialias import AntialiasPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.render_core import CapturePass

SIZE = (320, 180)
SSAA = 4
FRAMES = 24
TURN = math.radians(0.5)
SLIDE = 0.02              # metres a frame the box moves to its right in the "sliding" case
CHASE = 0.2               # metres a frame the box and the camera move together in the "chasing" case
BOX = (0.0, 2.0, -8.0)


def scene(gpu, *plugins):
    app = App(gpu).add_plugins(DefaultPlugins(fly_camera=False), SkyGradientPlugin(), GroundPlugin(), MeshPlugin(),
                               *plugins)
    app.world.create_entity(Transform(BOX, yaw=0.5, roll=0.3), MeshInstance(box((3, 3, 3)), (0.9, 0.2, 0.1)))
    return app, app.graph.add_pass(CapturePass())


def aim(app, n: int, turn: float, slide: float = 0.0, chase: bool = False) -> None:
    """Frame ``n``'s view: the camera turned ``turn`` radians a frame, the box moved ``slide`` m a frame (and
    the camera with it when ``chase``)."""
    cam = app.resource(Camera)
    cam.position = np.array([slide * n if chase else 0.0, 2.0, 0.0])
    cam.yaw, cam.pitch = -0.2 + turn * n, -0.05
    for _, transform in app.world.get_component(Transform):
        transform.teleport(np.array(BOX) + (slide * n, 0.0, 0.0))


def shown(hdr):
    return np.clip(hdr[..., :3] / (1.0 + hdr[..., :3]), 0.0, 1.0) ** (1 / 2.2)


def references(turn: float, slide: float = 0.0, chase: bool = False) -> list[np.ndarray]:
    """The 4x4 supersampled frame (as displayed, then averaged) of each of the FRAMES views."""
    w, h = SIZE
    gpu = create_headless((w * SSAA, h * SSAA))
    try:
        app, capture = scene(gpu)
        out = []
        for n in range(FRAMES):
            aim(app, n, turn, slide, chase)
            app.update(0.0)
            out.append(shown(capture.color).reshape(h, SSAA, w, SSAA, 3).mean(axis=(1, 3)))
        app.close()
        return out
    finally:
        gpu.release()


def run(mode: str | None, turn: float, refs, slide: float = 0.0, motion: bool = True,
        chase: bool = False) -> tuple[float, float]:
    """(relative RMSE against the references: the last frame still, the mean of the last half moving;
    GPU ms of the anti-aliasing pass)."""
    gpu = create_headless(SIZE)
    try:
        plugins = () if mode is None else (AntialiasPlugin(mode=mode, motion=motion),)
        app, capture = scene(gpu, *plugins)
        app.graph.timings_enabled = True
        errors = []
        for n in range(FRAMES):
            aim(app, n, turn, slide, chase)
            app.update(0.0)
            image = shown(capture.color)
            errors.append(float(np.sqrt(np.mean((image - refs[n]) ** 2)) / refs[n].mean()))
        name = {"fxaa": "antialias", "taa": "temporal_aa"}.get(mode)
        ms = app.graph.timings.get(name, (float("nan"),))[0] if name else 0.0
        app.close()
        return (errors[-1] if turn == slide == 0.0 else float(np.mean(errors[FRAMES // 2:]))), ms
    finally:
        gpu.release()


def main() -> None:
    print(f"anti-aliasing, {SIZE[0]}x{SIZE[1]}, against {SSAA}x{SSAA} supersampling (relative RMSE as displayed)")
    print(f"{'mode':>14} {'still':>8} {'turning':>8} {'sliding':>8} {'chasing':>8} {'pass ms':>8}")
    cases = {"still": references(0.0), "turning": references(TURN), "sliding": references(0.0, SLIDE),
             "chasing": references(0.0, CHASE, True)}
    for mode, motion, name in ((None, True, "none"), ("fxaa", True, "fxaa"), ("taa", True, "taa"),
                               ("taa", False, "taa no motion")):
        still, ms = run(mode, 0.0, cases["still"], motion=motion)
        turning, _ = run(mode, TURN, cases["turning"], motion=motion)
        sliding, _ = run(mode, 0.0, cases["sliding"], SLIDE, motion=motion)
        chasing, _ = run(mode, 0.0, cases["chasing"], CHASE, motion=motion, chase=True)
        print(f"{name:>14} {100 * still:7.2f}% {100 * turning:7.2f}% {100 * sliding:7.2f}% {100 * chasing:7.2f}% "
              f"{ms:8.2f}")


if __name__ == "__main__":
    main()
