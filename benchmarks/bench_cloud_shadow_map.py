"""Cloud shadow map vs the exact column sums: the error of exp(-tau) over the sunset demo (at the light
shafts' march points and at ground points, by cascade) and the work per frame; with a GPU also the
shadow and shaft passes' GPU ms with the map and with the column sums per lookup.
`.venv/bin/python benchmarks/bench_cloud_shadow_map.py [--timings]`."""
from __future__ import annotations

import math
import sys

import numpy as np

from atmos import create_headless
from atmos.camera import Camera, view_basis
from atmos.demo_registry import DemoSettings
from atmos.lighting import Sun, unit_sun
from atmos.plugins.clouds.shadows import CloudShadowsPass
from atmos.plugins.clouds.shadows.probe import ShadowMapProbe
from atmos.plugins.clouds.shadows.shadow_map import MAP_SIZE, NEAR_RATIO
from atmos.plugins.light_shafts import LightShaftSettings
from atmos.plugins.light_shafts.march import MarchedShafts
from atmos.runner import build_app

SIZE = (320, 180)


def shaft_points(cam, aspect: float, steps: int, reach: float, factor: int = 4) -> np.ndarray:
    """The march's sample points of every low-res texel (mid-step), out to ``reach`` or the ground (y = 0)."""
    w, h = SIZE[0] // factor, SIZE[1] // factor
    right, up, forward = (np.asarray(v, np.float64) for v in view_basis(cam, aspect)[:3])
    u, v = np.meshgrid((np.arange(w) + 0.5) / w * 2 - 1, (np.arange(h) + 0.5) / h * 2 - 1)
    d = forward + u[..., None] * right + v[..., None] * up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    far = np.where(d[..., 1] < 0, np.minimum(cam.position[1] / np.maximum(-d[..., 1], 1e-6), reach), reach)
    s = (np.arange(steps) + 0.5) / steps
    return (cam.position + d[..., None, :] * (far[..., None, None] * s[:, None])).reshape(-1, 3)


def ground_points(cam, n: int, near: float, reach: float, rng) -> np.ndarray:
    """Points on the ground (y in [0, 500], the terrain's relief) from ``near`` to ``reach`` from the camera."""
    r, a = np.sqrt(rng.uniform(near ** 2, reach ** 2, n)), rng.uniform(0, 2 * math.pi, n)
    return np.stack([cam.position[0] + r * np.cos(a), rng.uniform(0, 500, n), cam.position[2] + r * np.sin(a)], -1)


def errors(result) -> tuple[float, float]:
    e = np.exp(-result[:, 0]) - np.exp(-result[:, 1])
    return float(np.abs(e).max()), float(np.sqrt(np.mean(e * e)))


def accuracy(frames: int = 4) -> None:
    gpu = create_headless(SIZE)
    app = build_app("sunset", DemoSettings(size=SIZE, headless=True), gpu)
    probe = app.graph.add_pass(ShadowMapProbe(app.graph))
    app.run_frames(frames, 1 / 30)
    cam, sun = app.resource(Camera), unit_sun(app.resource(Sun).direction)
    steps = LightShaftSettings().steps
    reach = LightShaftSettings().max_distance
    sets = {f"shaft steps ({reach / 1000:.0f} km)": shaft_points(cam, SIZE[0] / SIZE[1], steps, reach)}
    for r0, r1 in ((0.0, 5e3), (5e3, 20e3), (20e3, cam.far)):
        sets[f"ground {r0 / 1000:.0f}-{r1 / 1000:.0f} km"] = ground_points(cam, 50000, r0, r1, np.random.default_rng(7))
    print(f"sunset, sun elevation {math.degrees(math.asin(sun[1])):.1f} deg; error of exp(-tau), map - exact:")
    print(f"{'points':22s} {'n':>7s} {'near: max':>10s} {'rms':>8s} {'far: max':>10s} {'rms':>8s} {'far texel':>10s}")
    far_widths = []
    for name, pts in sets.items():
        probe.points = pts
        app.run_frames(1, 1 / 30)
        r = probe.result
        space = next(p for p in app.graph.passes if p.name == "cloud_shadow_map").space
        near = in_near(space, pts, sun)
        far_widths.append(space.read_at(space.plane_texel(pts, sun))[2][~near].mean() * space.cell[0])
        cells = [errors(r[m]) if m.any() else (0.0, 0.0) for m in (near, ~near)]
        print(f"{name:22s} {len(pts):7d} {cells[0][0]:10.4f} {cells[0][1]:8.4f} {cells[1][0]:10.4f} {cells[1][1]:8.4f} {far_widths[-1]:8.1f} m")
    n = space.size
    print(f"map {n}x{2 * n} rg16f; near {1 / space.cascades[0, 2]:.0f} texels per cell, {space.near}x{space.near} in use "
          f"({space.cell[0] * space.cascades[0, 2]:.1f} m), far {far_width(space, 0.0):.1f} m texels at its centre, "
          f"{far_width(space, 1.0):.1f} m at its edge ({space.cell[0] * space.far_offsets(np.full(2, n - 1.0))[0] / 1000:.0f} km)")
    app.close()
    gpu.release()


def in_near(space, pts, sun) -> np.ndarray:
    return space.read_at(space.plane_texel(pts, sun))[1]


def far_width(space, u: float) -> float:
    """The far cascade's texel width in metres (x) at ``u`` of its half-width from its centre."""
    c = space.far_centre_index
    j = np.array([[c + u * c - 1.0] * 2, [c + u * c] * 2]) if u > 0 else np.array([[c] * 2, [c + 1.0] * 2])
    return float(np.diff(space.far_offsets(j)[:, 0])[0] * space.cell[0])


def work() -> None:
    steps = LightShaftSettings().steps
    n = MAP_SIZE
    print("work per frame (sunset, far field on): texture fetches per tau lookup")
    print(f"  exact: 8 column fetches (4 bilinear taps x A, B) + 4 octaves + 1 rank table = 13; "
          f"per shaft texel x {steps} steps = {13 * steps}")
    print(f"  map:   1 bilinear fetch; per shaft texel x {steps} steps = {steps}; "
          f"+ 1 bake dispatch: {n}x{n} far texels and the near cascade's in use (at most {NEAR_RATIO} per cell "
          f"each way) x 13 fetches")


def timings(frames: int = 30) -> None:
    """GPU ms of the shadows, shafts and bake with the map and with the exact sums (a GPU's timer queries)."""
    for exact in (True, False):
        CloudShadowsPass.exact = MarchedShafts.exact = exact
        gpu = create_headless((1920, 1080))
        app = build_app("sunset", DemoSettings(size=(1920, 1080), headless=True), gpu)
        app.graph.timings_enabled = True
        app.run_frames(5, 1 / 30)
        total: dict[str, float] = {}
        for _ in range(frames):
            app.run_frames(1, 1 / 30)
            for k in ("cloud_shadow_map", "cloud_shadows", "light_shafts"):
                total[k] = total.get(k, 0.0) + app.graph.timings.get(k, (0.0, 0.0))[0] / frames
        print(("exact" if exact else "map  "), "  ".join(f"{k} {v:.2f} ms" for k, v in total.items()))
        app.close()
        gpu.release()
    CloudShadowsPass.exact = MarchedShafts.exact = False


if __name__ == "__main__":
    accuracy()
    work()
    if "--timings" in sys.argv:
        timings()
