"""Soak: thousands of frames of the cloud scene with weather churn, live setting changes, time-of-day
jumps and window resizes; then 50 Apps created and closed in one process.

The scene (sky with daylight, ground, clouds with shadows and light shafts, small: 160×90, a 32×8×32
volume) runs ``--frames`` frames at 1/30 s. Every frame the viewer drifts (VolumeOrigin); every 20
frames the window takes the next of 6 sizes; every 45 frames the weather's cloud density changes;
every 60 frames 3 ellipsoids are added with ``add_ellipsoid`` and 2 deleted; every 37 frames a plugin
setting changes (``configure``) and every 250 frames a bad one is refused; every 75 frames the time
of day jumps (day and night by turns) and the camera turns toward the sun; every 500 frames an ellipsoid made by hand with a NaN radius is skipped (one warning).

Printed: host RSS (raw and after ``malloc_trim``, sampled once per cycle of sizes) and live GL
objects (:class:`atmos.gpu.census.GLCensus`, every frame) as the maximum over the first quarter and
over the last quarter (bounded caches fill and drain; a leak shows as a higher last quarter), their
growth, and the errors (exceptions); then the same for 50 Apps made and closed
one after another on one shared context, and for 50 Apps each on a context of its own. Goal: ≤ 2 %
memory, 0 GL objects and 0 errors over 20,000 frames.

    python benchmarks/bench_soak.py [--frames 20000] [--apps 50]
"""
from __future__ import annotations

import argparse
import gc
import math
import sys
import time
import warnings
import weakref
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from bench_resize_memory import growth, rss_mb, trimmed_rss_mb  # noqa: E402

from atmos.app import App  # noqa: E402
from atmos.camera import Camera  # noqa: E402
from atmos.defaults import DefaultPlugins  # noqa: E402
from atmos.gpu import create_headless  # noqa: E402
from atmos.gpu.census import GLCensus  # noqa: E402
from atmos.plugins.clouds.sprites import CloudRenderPlugin  # noqa: E402
from atmos.plugins.clouds.weather.example import example_weather  # noqa: E402
from atmos.plugins.clouds.shadows import CloudShadowsPlugin  # noqa: E402
from atmos.plugins.clouds import CloudSettings, CloudsPlugin  # noqa: E402
from atmos.plugins.daylight import DaylightPlugin  # noqa: E402
from atmos.plugins.ground import GroundPlugin  # noqa: E402
from atmos.plugins.light_shafts import LightShaftsPlugin  # noqa: E402
from atmos.plugins.sky import SkyPlugin  # noqa: E402
from atmos.plugins.clouds.weather import Ellipsoid, VolumeOrigin, add_ellipsoid  # noqa: E402

SIZE = (160, 90)
SIZES = [(160, 90), (171, 95), (150, 84), (193, 108), (128, 72), (177, 100)]
FRAMES_PER_SIZE = 20
CYCLE = FRAMES_PER_SIZE * len(SIZES)
GOAL_MEMORY_PERCENT = 2.0
SETTING_CHANGES = [   # (plugin type, changes), cycled every 37 frames
    (LightShaftsPlugin, dict(exposure=0.8)), (LightShaftsPlugin, dict(exposure=0.5)),
    (CloudRenderPlugin, dict(size_factor=3.5)), (CloudRenderPlugin, dict(size_factor=3.0)),
    (SkyPlugin, dict(turbidity=4.0)), (SkyPlugin, dict(turbidity=3.0)),
    (CloudShadowsPlugin, dict(strength=0.5)), (CloudShadowsPlugin, dict(strength=0.8)),
]


def cloud_scene(gpu) -> App:
    weather = example_weather((32, 8, 32), 30)
    clouds = CloudsPlugin(CloudSettings(weather=weather, smoothing_slices=2, group_size=(8, 8),
                                        cell_size=(20.0, 15.0, 20.0), base_altitude=300.0), seed=7, warmup_steps=4)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=True), DaylightPlugin(hours=15.0), SkyPlugin(), GroundPlugin(),
                               clouds, CloudRenderPlugin(), CloudShadowsPlugin(), LightShaftsPlugin())
    cam = app.resource(Camera)
    cam.position, cam.far = np.array([320.0, 60.0, 320.0]), 6000.0      # under the middle of the cloud layer
    return app


def plugin_of(app, kind):
    return next(p for p in app.plugins if isinstance(p, kind))


def churn(app, gpu, i: int, rng, log: dict) -> None:
    """What happens before frame ``i``."""
    clouds = plugin_of(app, CloudsPlugin)
    origin = app.resource(VolumeOrigin)
    origin.x += 0.05                                     # the viewer drifts
    if i % FRAMES_PER_SIZE == 0:
        gpu.resize(SIZES[(i // FRAMES_PER_SIZE) % len(SIZES)])
    if i % 45 == 0:
        clouds.configure(weather={"cloud_density": int(20 + 20 * (1 + math.sin(i / 300)))})
    if i % 60 == 0:
        o, shape = origin, clouds.settings.weather.volume_shape
        for _ in range(3):
            add_ellipsoid(app.world, x=o.x + rng.uniform(0, shape[0]), y=o.y + shape[1] / 2, z=o.z + rng.uniform(0, shape[2]),
                          rx=rng.uniform(3, 6), ry=2.0, rz=rng.uniform(3, 6), lifetime=rng.uniform(20, 60))
        for entity, _ in sorted(app.world.get_component(Ellipsoid))[:2]:
            app.world.delete_entity(entity, immediate=True)
    if i % 37 == 0:
        kind, changes = SETTING_CHANGES[(i // 37) % len(SETTING_CHANGES)]
        plugin_of(app, kind).configure(**changes)
    if i % 250 == 0:
        try:
            plugin_of(app, SkyPlugin).configure(turbidity=math.nan)
        except ValueError:
            log["refused"] += 1
    if i % 75 == 0:                                      # day and night by turns (night skips some passes)
        daylight = plugin_of(app, DaylightPlugin)
        daylight.configure(hours=float((15.0 + 12.0 * (i // 75 % 2) + rng.uniform(-2, 2)) % 24))
        cam = app.resource(Camera)                       # toward the sun, under the clouds: shafts on screen
        toward = daylight.sun_direction()
        cam.look_at(cam.position + 100.0 * np.array([toward[0], max(toward[1], 0.3), toward[2]]))
    if i % 500 == 250:
        app.world.create_entity(Ellipsoid(x=origin.x + 8, y=4.0, z=origin.z + 8, rx=math.nan, lifetime=30.0))
        log["bad_ellipsoids"] += 1


def soak(frames: int, seed: int = 0, census: GLCensus | None = None) -> dict:
    """Run the soak; returns the samples and counts (see the module docstring)."""
    rng = np.random.default_rng(seed)
    own = census is None
    census = census or GLCensus()
    log = {"errors": [], "refused": 0, "bad_ellipsoids": 0, "warnings": 0}
    memory, objects = [], []                             # (rss MiB, trimmed MiB) a cycle; live GL objects a frame
    if own:
        census.__enter__()
    try:
        gpu = create_headless(SIZE)
        app = cloud_scene(gpu)
        start = time.perf_counter()
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for i in range(frames):
                try:
                    churn(app, gpu, i, rng, log)
                    app.update(1 / 30)
                except Exception as error:            # counted, and the soak goes on: it must not happen
                    log["errors"].append(f"frame {i}: {type(error).__name__}: {error}")
                objects.append(census.total(gpu.ctx))
                if i % CYCLE == CYCLE - 1:
                    memory.append((rss_mb(), trimmed_rss_mb()))
            log["warnings"] = sum(1 for w in caught if "removed invalid ellipsoid" in str(w.message))
        seconds = time.perf_counter() - start
        if gpu.ctx.error != "GL_NO_ERROR":
            log["errors"].append("an OpenGL error was left at the end")
        app.close()
        gpu.release()
    finally:
        if own:
            census.__exit__(None, None, None)
    return {"frames": frames, "seconds": seconds, "memory": memory, "objects": objects, **log}


def apps_churn(n: int, shared: bool, census: GLCensus) -> dict:
    """``n`` cloud-scene Apps made, run 5 frames and closed one after another: on one shared context
    (live GL objects of it after each) or each on its own context (contexts still alive after each)."""
    memory, objects, errors = [], [], []
    shared_gpu = create_headless(SIZE) if shared else None
    contexts = []
    for k in range(n):
        gpu = shared_gpu or create_headless(SIZE)
        try:
            app = cloud_scene(gpu)
            app.run_frames(5, dt=1 / 30)
            app.close()
            del app
        except Exception as error:
            errors.append(f"app {k}: {type(error).__name__}: {error}")
        if not shared:
            contexts.append(weakref.ref(gpu.ctx))
            gpu.release()
        del gpu
        census.live()                                     # forgets released objects (they hold their context)
        gc.collect()
        objects.append(census.total(shared_gpu.ctx) if shared else sum(ref() is not None for ref in contexts))
        memory.append((rss_mb(), trimmed_rss_mb()))
    if shared_gpu is not None:
        shared_gpu.release()
    return {"apps": n, "memory": memory, "objects": objects, "errors": errors}


def quarter_max(samples: list) -> tuple:
    """(maximum over the first quarter, maximum over the last quarter) of ``samples``."""
    q = max(1, len(samples) // 4)
    return max(samples[:q]), max(samples[-q:])


def report(title: str, result: dict, objects: str) -> bool:
    """Print a result's first → last quarter table; True when the goal is met."""
    errors = result["errors"]
    print(f"\n{title}")
    print(f"  {'':22} {'first quarter':>14} {'last quarter':>14} {'growth':>9}")
    ok = not errors
    trimmed = result["memory"][0][1] is not None
    for column, name in ((0, "host RSS MiB"), (1, "RSS trimmed MiB")):
        if column == 1 and not trimmed:
            continue
        a, b = quarter_max([m[column] for m in result["memory"]])
        print(f"  {name:22} {a:14.1f} {b:14.1f} {growth(a, b):+8.2f}%")
        if column == int(trimmed):                       # the goal on trimmed RSS where glibc can trim
            ok &= growth(a, b) <= GOAL_MEMORY_PERCENT
    a, b = quarter_max(result["objects"])
    print(f"  {objects:22} {a:14d} {b:14d} {b - a:+9d}")
    ok &= b <= a
    print(f"  errors: {len(errors)}" + "".join(f"\n    {e}" for e in errors[:5]))
    print(f"  goal (≤ {GOAL_MEMORY_PERCENT:g} % memory, 0 {objects}, 0 errors): {'met' if ok else 'MISSED'}")
    return ok


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20000)
    parser.add_argument("--apps", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    with GLCensus() as census:
        result = soak(args.frames, args.seed, census)
        print(f"soak: {result['frames']} frames of the cloud scene at {SIZE[0]}x{SIZE[1]} (resized every "
              f"{FRAMES_PER_SIZE} frames over {len(SIZES)} sizes) in {result['seconds']:.0f} s "
              f"({result['seconds'] / result['frames'] * 1000:.1f} ms/frame); refused bad settings: {result['refused']}; "
              f"bad ellipsoids skipped: {result['warnings']} of {result['bad_ellipsoids']}")
        ok = report("soak", result, "live GL objects")
        ok &= report(f"{args.apps} Apps on one shared context", apps_churn(args.apps, True, census), "live GL objects")
        ok &= report(f"{args.apps} Apps, each on its own context", apps_churn(args.apps, False, census), "contexts alive")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
