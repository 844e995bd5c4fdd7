"""The cloud shadow map (plugins/clouds/shadows/shadow_map.py): its float64 lookup against the exact
sun_optical_depth within the derived interpolation bound, the GPU's bake and lookup against float64, and
the shadow pass on the map against lookup_reference."""
import copy
import math

import numpy as np
import pytest

from atmos.camera import Camera
from atmos.graph import RenderPass
from atmos.lighting import Sun, unit_sun
from atmos.plugins.clouds.shadows import CloudShadowSettings, reference
from atmos.plugins.clouds.shadows.probe import ShadowMapProbe
from atmos.plugins.clouds.shadows.shadow_map import (FORMAT_ERROR, SHADOW_MAP, SHADOW_SPACE, bake_reference,
                                                     lookup_reference, shadow_space)
from atmos.plugins.clouds.volume.layout import CloudLayout
from test_cloud_shadows import draw_typed, shadow_app, write_sums


def edge_derivatives(shape, fade: float):
    """Bounds on the edge weight's first and second derivatives per volume texel, per axis (x, z):
    f = 1 - smoothstep(1 - fade, 1, r), r = |2 uv - 1|, uv = (v + 0.5) / shape."""
    d = 2.0 / np.array([shape[0], shape[2]], np.float64)            # |dr/dv| per axis
    first = 1.5 / fade * d
    second = 6.0 / fade ** 2 * d ** 2 + 1.5 / fade * d ** 2 / (1.0 - fade)   # r's curvature: d² / r, r >= 1 - fade
    return first, second


def test_float64_lookup_matches_sun_optical_depth_within_the_derived_bound(rng):
    """Bilinear interpolation on a map cell of h volume texels errs by at most h²/8 · Σ_axes max|g_aa|;
    the volume's columns c are bilinear on every map cell (texel centres on the columns), so for
    g = c · f only 2 c_a f_a + c f_aa is left; the far column F · (1 - f) (here a smooth pattern of
    amplitude A, wavenumber k) adds F_aa + 2 F_a f_a + F f_aa."""
    shape = (int(rng.integers(16, 48)), 6, int(rng.integers(16, 48)))
    cell = tuple(rng.uniform([20.0, 10.0, 20.0], [60.0, 50.0, 60.0]))
    layout = CloudLayout(shape, cell, (float(rng.integers(-40, 0)), float(rng.integers(-40, 0))),
                         rng.uniform(500, 1500), (8, 8), 0.0)
    sums_a, sums_b = (rng.uniform(0, shape[1], (shape[0], shape[2])) for _ in range(2))
    t, fade = rng.uniform(), rng.uniform(0.2, 0.5)
    a_shift = (int(rng.integers(-3, 4)), 0, int(rng.integers(-3, 4)))
    sun = unit_sun(Sun.from_angles(rng.uniform(4, 60), rng.uniform(0, 360)).direction)
    ext, field_tau, amp, k = rng.uniform(0.05, 0.5), rng.uniform(0.05, 0.5), rng.uniform(1, 4), 2 * math.pi / 600.0
    far = lambda xz: amp * (1.0 + np.sin(k * xz[..., 0]) * np.cos(k * xz[..., 1]))
    centre = layout.lo + 0.5 * (layout.hi - layout.lo)
    cam = centre + np.array([rng.uniform(-300, 300), -centre[1] + rng.uniform(50, 400), rng.uniform(-300, 300)])
    space = shadow_space(layout, cam, sun, 6000.0, size=256)
    baked = bake_reference(space, sums_a, sums_b, t, layout, a_shift, fade, far)
    n = 20000
    pts = cam + np.stack([rng.uniform(-5000, 5000, n), rng.uniform(-cam[1], layout.hi[1] + 50 - cam[1], n),
                          rng.uniform(-5000, 5000, n)], -1)
    exact = reference.sun_optical_depth(pts, sums_a, sums_b, t, sun, ext, layout, a_shift, fade,
                                        far=lambda xz: field_tau * far(xz))
    got = lookup_reference(space, baked, pts, sun, (ext, field_tau))
    # which cascade each point read, and its texel size h (volume texels); points past the far one clamp
    v = space.plane_texel(pts, sun)
    _, near, h = space.read_at(v)           # h: the width of the (warped) map cell each point falls in
    far = space.far_index(v)
    inside = near | np.all((far >= 0) & (far <= space.size - 1), axis=-1)
    sums = (1 - t) * reference.shifted(sums_a, a_shift) + t * sums_b
    c_max = sums.max()
    c_a = np.array([np.abs(np.diff(sums, axis=0)).max(), np.abs(np.diff(sums, axis=1)).max()])
    f_a, f_aa = edge_derivatives(shape, fade)
    cell_xz = np.array([cell[0], cell[2]])
    F, F_a, F_aa = 2 * amp, amp * k * cell_xz, amp * (k * cell_xz) ** 2
    g_aa = ext * (2 * c_a * f_a + c_max * f_aa) + field_tau * (F_aa + 2 * F_a * f_a + F * f_aa)
    above = np.clip((layout.hi[1] - pts[:, 1]) / (layout.hi[1] - layout.lo[1]), 0, 1)
    bound = (h ** 2 / 8.0 * g_aa).sum(-1) * above + 1e-12
    err = np.abs(got - exact)
    assert inside.mean() > 0.5          # the rest project past the far cascade (clamped)
    assert np.all(err[inside] <= bound[inside]), f"worst ratio {(err / bound)[inside].max()}"
    e = np.abs(np.exp(-got) - np.exp(-exact))[inside]
    print(f"near {near.mean():.2f}; exp(-tau) max {e.max():.2e}, rms {np.sqrt(np.mean(e * e)):.2e}; "
          f"error / bound max {(err / bound)[inside].max():.2f}")


class MapCapture(RenderPass):
    """Reads the shadow map and its space back after the bake."""
    name = "shadow_map_capture"
    phase = "post"

    def __init__(self):
        self.map = self.space = None

    def setup(self, builder) -> None:
        builder.read(SHADOW_MAP)
        builder.read(SHADOW_SPACE)
        builder.side_effect()

    def execute(self, frame) -> None:
        texture = frame.resource(SHADOW_MAP)
        w, h = texture.size
        self.map = np.frombuffer(texture.read(), "f2").reshape(h, w, 2).astype(np.float64)
        s = frame.resource(SHADOW_SPACE)
        self.space = copy.deepcopy(s)


@pytest.mark.parametrize("typed", [None, "type", "map"])
def test_gpu_bake_and_lookup_match_float64(gpu, ctx, rng, typed):
    """The bake against bake_reference within rg16f's rounding (2^-11 relative) and float32's; the GPU
    lookup (one bilinear fetch) against lookup_reference on the GPU's own map within the filter's
    weight precision (8 fractional bits on some GPUs: 2^-9 of the largest neighbour difference). With
    the clouds drawn with a cloud type (one, or a map) the columns are the shape drawn, in the bake and
    in the exact path alike."""
    cell = tuple(rng.uniform([3.0, 1.0, 3.0], [8.0, 3.0, 8.0]))
    app, sim, fill, _ = shadow_app(gpu, CloudShadowSettings(), cell_size=cell)
    types = draw_typed(app, sim, rng, typed)
    capture, probe = MapCapture(), ShadowMapProbe(app.graph)
    app.graph.add_pass(capture)
    app.graph.add_pass(probe)
    for _ in range(2):
        app.update(1 / 30)
    a, b, t = sim.view()
    nx, ny, nz = sim.shape
    layers = 1 + sim.maps_of(a).bands
    sums = [rng.uniform(0, ny, (layers, nx, nz)) for _ in range(2)]
    write_sums(sim, a, sums[0])
    write_sums(sim, b, sums[1])
    sets = sim.sets()
    layout = sets.layout()
    sun = Sun.from_angles(rng.uniform(10, 80), rng.uniform(0, 360))
    app.insert_resource(sun)
    s = unit_sun(sun.direction)
    cam = app.resource(Camera)
    centre = layout.lo + 0.5 * (layout.hi - layout.lo)
    cam.position = centre - s * 50.0
    n = 20000
    # points on sun rays through the volume's middle plane, from a little above it down to the ground
    mid = np.stack([layout.lo[0] + rng.uniform(-0.2, 1.2, n) * nx * cell[0], np.full(n, centre[1]),
                    layout.lo[2] + rng.uniform(-0.2, 1.2, n) * nz * cell[2]], -1)
    probe.points = mid - s * (rng.uniform(-0.1, 1.0, n) * centre[1] / s[1])[:, None]
    points = probe.points
    app.render()
    space = capture.space
    want = bake_reference(space, sums[0][0], sums[1][0], t, layout, sets.a_shift, sim.settings.edge_fade, **types)
    scale = want[..., 0].max()
    # float32 texel positions v0 + offset (v0, the step or K and w / c rounded to float32 on upload) move a
    # sample by a few ulps of |v0| + |offset|, which for the far cascade (v0 thousands of texels off)
    # exceeds |v|'s, and the far one's sinh(x) (two exps of 3 + 2|x| ulps each, and x's rounding) by
    # K cosh(x) (6 + 2|x|) ulps: times the columns' steepest slope per texel (their largest neighbour difference)
    from atmos.plugins.clouds.shadows.shadow_map import texel_positions
    slope = max(np.abs(np.diff(m[0], axis=a)).max() for m in sums for a in (0, 1))
    if typed is not None:     # a typed column moves by its steepest derivative in the sum times that
        from atmos.plugins.clouds.volume.shape import typed_column
        col = np.linspace(0.0, ny, 4001)
        tt = [types["cloud_type"]] if typed == "type" else np.linspace(0.0, 1.0, 21)
        slope *= max(np.abs(np.diff(typed_column(col, 0.0, 0.0, ny, t_, None))).max() / (col[1] - col[0]) for t_ in tt)
    v = texel_positions(space)
    start = np.repeat(space.cascades[:, :2], space.size, axis=0)[:, None, :]       # near: texel 0; far: the centre
    x = np.arcsinh((v - start) / space.cascades[1, 2:]) * (np.arange(2 * space.size) >= space.size)[:, None, None]
    sinh = space.cascades[1, 2:] * np.cosh(x) * (6.0 + 2.0 * np.abs(x))
    moved = 2.0 ** -24 * (4 * (np.abs(start) + np.abs(v - start)) + sinh).max(-1, keepdims=True) * slope
    # (typed: 32 float32 terms of the profile, each a few roundings: 2^-16 of the column)
    error = np.abs(capture.map - want) - (2 * FORMAT_ERROR + (2.0 ** -16 if typed else 0.0)) * np.abs(want) - 1e-5 * scale - moved
    assert error.max() <= 0.0, f"bake error over the bound by {error.max()} at {np.unravel_index(error.argmax(), error.shape)}"
    exact, got = probe.result[:, 0], probe.result[:, 1]
    mine = lookup_reference(space, capture.map, points, s, probe.weights)
    step = max(np.abs(np.diff(capture.map[..., 0], axis=a)).max() for a in (0, 1)) * probe.weights[0]
    assert np.all(np.abs(got - mine) <= 2.0 ** -9 * 2 * step + 1e-5 * scale * probe.weights[0])
    # the map against the exact sums on the GPU: edge fade off (sim's default), the columns are exact;
    # typed, the map interpolates typed(sum) between its texels where the exact path types the
    # interpolated sum: a convex mix of corner sums spread over L, of a function whose slope lies in
    # [0, g'max], errs by at most g'max L / 4; L <= the sums' steepest step per volume texel x (h_x + h_z),
    # h the cascade's texel in volume texels; and the exact path against its float64 twin
    interp = 0.0
    if typed is not None:
        g1 = max(np.abs(np.diff(typed_column(col, 0.0, 0.0, ny, t_, None))).max() / (col[1] - col[0]) for t_ in tt)
        v = space.plane_texel(points, s)
        h = space.read_at(v)[2]
        raw = max(np.abs(np.diff(m[0], axis=a)).max() for m in sums for a in (0, 1))
        interp = g1 * raw * h.sum(-1) / 4.0 * probe.weights[0]
        print(f"typed: |map - exact| max {np.abs(got - exact).max():.3g}, bound median {np.median(interp):.3g}")
        want_exact = reference.sun_optical_depth(points, sums[0][0], sums[1][0], t, s, probe.weights[0], layout,
                                                 sets.a_shift, sim.settings.edge_fade, **types)
        # float32 point positions move the projected texel by a few ulps of |v| (times the typed slope)
        ulps = 8 * 2.0 ** -24 * np.abs(v).max() * slope * probe.weights[0]
        np.testing.assert_allclose(exact, want_exact, rtol=2.0 ** -16, atol=1e-5 * scale * probe.weights[0] + ulps)
    assert np.all(np.abs(got - exact) <= 2.0 ** -9 * 2 * step + 2 * FORMAT_ERROR * np.abs(exact)
                  + 1e-5 * scale * probe.weights[0] + interp)
    assert (exact > 0.1).mean() > 0.1, "the points are under clouds"
    app.close()


def test_the_shadow_pass_on_the_map_matches_lookup_reference(gpu, ctx, rng):
    """cloud_shadows on the shadow map (shadows at the volume's own placement): each ground pixel's
    colour times 1 − weight (1 − exp(−τ)), τ from lookup_reference on the GPU's own map at the point
    behind the pixel; sky pixels and alpha (the sky occlusion) kept."""
    from test_cloud_shadows import depth_of, ray_dirs, world_points
    size = gpu.size
    cell = tuple(rng.uniform([3.0, 1.0, 3.0], [8.0, 3.0, 8.0]))
    params = CloudShadowSettings(sigma=rng.uniform(0.2, 1.0), strength=rng.uniform(0.5, 2.0),
                                 direct_fraction=rng.uniform(0.5, 1.0))
    app, sim, fill, probe = shadow_app(gpu, params, cell_size=cell)
    capture = MapCapture()
    app.graph.add_pass(capture)
    for _ in range(2):
        app.update(1 / 30)
    a, b, _ = sim.view()
    nx, ny, nz = sim.shape
    layers = 1 + sim.maps_of(a).bands
    for s in (a, b):
        write_sums(sim, s, rng.uniform(0, ny, (layers, nx, nz)))
    layout = sim.sets().layout()
    sun = Sun.from_angles(rng.uniform(20, 85), rng.uniform(0, 360), color=tuple(rng.uniform(0.2, 2, 3)))
    app.insert_resource(sun)
    centre = layout.lo + 0.5 * (layout.hi - layout.lo)
    shadow = centre - sun.direction * centre[1] / sun.direction[1]      # where the layer's shadow falls
    shadow[1] = 0.0
    cam = app.resource(Camera)
    cam.near, cam.far = 1.0, 1000.0
    cam.position = shadow + np.array([rng.uniform(-60, 60), rng.uniform(30, 250), rng.uniform(-60, 60)])
    cam.look_at(shadow + np.array([rng.uniform(-20, 20), 0.0, rng.uniform(-20, 20)]))
    h, w = size[1], size[0]
    rays = ray_dirs(cam, size)
    to_ground = np.where(rays[..., 1] < 0, cam.position[1] / np.maximum(-rays[..., 1], 1e-9), np.inf)
    depth = depth_of(cam, size, cam.position + rays * np.minimum(to_ground, 300.0)[..., None])
    depth[rng.random((h, w)) < 0.1] = 1.0       # sky pixels stay as they are
    color = rng.uniform(0.5, 2.0, (h, w, 4))
    fill.color, fill.depth = color, depth
    app.render()                                # render only: the sets stay as written
    assert capture.space is not None and np.isfinite(probe.color).all()
    weight = reference.direct_weight(sun.direction, sun.color, params)
    tau = lookup_reference(capture.space, capture.map, world_points(cam, size, probe.depth), unit_sun(sun.direction),
                           (params.sigma * params.strength, 0.0))
    expected = np.where(probe.depth >= 1.0, 1.0, 1.0 - weight * -np.expm1(-tau))
    before = color.astype(np.float16).astype(np.float64)
    error = np.abs(probe.color[..., :3] / before[..., :3] - expected[..., None]).max(-1)
    # 2^-11: the f2 colour; float32 depth moves a few far points over the random map's texels
    assert np.quantile(error, 0.995) < 2e-3 and error.max() < 1e-2, f"max error {error.max()}"
    assert np.array_equal(probe.color[..., 3], before[..., 3])
    assert (expected < 0.95).sum() > 500, "the random scene has shadows to compare"
    app.close()
