"""The terrain to the horizon: the far ring's mesh continues the square vertex for vertex (no seam, gap
or T-junction), the far plane it needs costs the near view no depth precision, a rendered view has
ground under every ray below the horizon; the material's GLSL against its float64 twin on random
inputs; the mean albedo; the settings."""
import math

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.gpu.uniforms import bind_buffers, write_uniforms
from atmos.lighting import Sun
from atmos.plugins.terrain import TerrainPlugin, TerrainSettings, heightfield, terrain_mesh
from atmos.plugins.terrain import material
from atmos.plugins.terrain.heightfield import FAR_GROWTH, height, terrain_axis
from atmos.render_core import CapturePass
from test_cloud_shadows import pass_plugin

EPS32 = 2.0 ** -24          # float32's relative rounding (half an ulp)


# -- the mesh ------------------------------------------------------------------------------------
@pytest.mark.parametrize("size, cells, relief, horizon", [(256.0, 71, 30.0, 150000.0), (40000.0, 71, 500.0, 150000.0),
                                                          (12000.0, 96, 260.0, 2.0e5), (50.0, 3, 5.0, 51.0)])
def test_far_ring_continues_the_square_vertex_for_vertex(size, cells, relief, horizon):
    near_v, near_i = heightfield(size, cells, relief)
    v, i = terrain_mesh(size, cells, relief, horizon)
    axis = terrain_axis(size, cells, horizon)
    n, m = cells + 1, axis.size
    start = int(np.searchsorted(axis, -size / 2))
    assert axis[start] == -size / 2 and axis[start + cells] == size / 2
    assert axis[0] == -horizon and axis[-1] == horizon and np.all(np.diff(axis) > 0)
    steps = np.diff(axis[start + cells:])
    assert steps[0] <= FAR_GROWTH * size / cells * (1 + 1e-12) or steps.size == 1
    assert np.all(steps[1:-1] <= FAR_GROWTH * steps[:-2] * (1 + 1e-9))      # growing by FAR_GROWTH...
    assert steps.size == 1 or steps[-1] <= 2 * FAR_GROWTH * steps[-2]         # ...to the last, cut at the horizon
    # the square's vertices, positions bit for bit; normals too inside it (on its border they take
    # the slope over the wider steps outside into account)
    grid = v.reshape(m, m, 6)[start:start + n, start:start + n]
    np.testing.assert_array_equal(grid[..., :3].reshape(-1, 3), near_v[:, :3])
    np.testing.assert_allclose(grid[1:-1, 1:-1, 3:], near_v.reshape(n, n, 6)[1:-1, 1:-1, 3:], atol=1e-6)
    # every vertex on the height formula: the border's heights are the square's own
    x, z = np.meshgrid(axis, axis, indexing="ij")
    np.testing.assert_array_equal(v[:, 1], height(x, z, relief, size).astype(np.float32).ravel())
    # watertight: every edge is shared by two triangles, except those on the outer edge of the ring
    tris = i.reshape(-1, 3)
    edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    assert set(count) <= {1, 2}
    outer = v[unique[count == 1]][..., [0, 2]]
    assert np.all(np.any(np.abs(np.abs(outer) - horizon) <= 1e-3 * horizon, axis=-1).all(-1))
    assert (count == 1).sum() == 4 * (m - 1)
    # the square's own triangles, in its order, come from the same quads (the collision mesh)
    assert i.size // 3 == 2 * (m - 1) ** 2 and near_i.size // 3 == TerrainPlugin(cells=cells).triangles


def test_without_a_far_ring_the_mesh_is_the_square():
    for horizon in (0.0, 128.0):
        v, i = terrain_mesh(256.0, 71, 30.0, horizon)
        hv, hi = heightfield(256.0, 71, 30.0)
        np.testing.assert_array_equal(v, hv)
        np.testing.assert_array_equal(i, hi)


def depth_step(camera: Camera, d: float) -> float:
    """m: how far apart in view depth two 24-bit depth values are at view depth ``d`` (float64)."""
    n, f = camera.near, camera.far
    slope = (1.0 / (d * d)) / (1.0 / n - 1.0 / f)           # d window depth / d view depth
    return 2.0 ** -24 / slope


def test_the_far_plane_of_the_horizon_costs_the_near_view_no_precision():
    terrain = TerrainPlugin(size=40000.0, cells=71, relief=500.0)          # the cloud demos' terrain, its default ring
    far = terrain.far_plane()
    assert far >= math.hypot(150000.0 + 20000.0, 150000.0 + 20000.0) + 1000.0
    assert terrain.far_plane(within=0.0) == pytest.approx(math.sqrt(2.0) * 150000.0 + 1000.0)
    with pytest.raises(ValueError, match=r"TerrainPlugin\.far_plane\.within"):
        terrain.far_plane(within=-1.0)
    before, after = Camera(near=1.0, far=20000.0), Camera(near=1.0, far=far)
    for d in (2.0, 10.0, 100.0, 1000.0, 10000.0):
        assert depth_step(after, d) / depth_step(before, d) == pytest.approx(1.0, abs=1e-4)
    assert depth_step(after, 10.0) < 1e-4 and depth_step(after, 1000.0) < 0.1
    assert depth_step(after, 150000.0) / 150000.0 < 0.01        # 1 % at the horizon: haze and fog keep working
    Camera(near=1.0, far=far).check()                           # a far / near the camera allows


# -- a rendered view -----------------------------------------------------------------------------
def render(gpu, horizon: float):
    """A near-level view over a 4 km square (with a far ring to ``horizon``): colour, depth, each
    pixel's ray elevation (radians) and distance from depth (GL row order), and the camera."""
    capture = CapturePass()
    terrain = TerrainPlugin(size=4000.0, cells=40, relief=60.0, horizon=horizon)
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False, fly_camera=False), terrain, pass_plugin(capture))
    app.startup()
    cam = app.resource(Camera)
    cam.position, cam.yaw, cam.pitch, cam.roll = np.array([300.0, 120.0, -200.0]), 0.7, -0.02, 0.0
    cam.near, cam.far = 1.0, terrain.far_plane()
    app.insert_resource(Sun(np.array([0.3, 0.5, -1.0])))
    app.render()
    color, depth = capture.color.copy(), capture.depth.copy()
    w, h = gpu.size
    x, y = np.meshgrid((np.arange(w) + 0.5) / w * 2 - 1, (np.arange(h) + 0.5) / h * 2 - 1)
    t = math.tan(cam.fov_y / 2)
    rays = np.stack([x * t * w / h, y * t, -np.ones_like(x)], -1) @ cam.view()[:3, :3]
    elevation = np.arcsin(rays[..., 1] / np.linalg.norm(rays, axis=-1))
    distance = cam.near / ((1.0 - depth) + depth * (cam.near / cam.far)) * np.linalg.norm(rays, axis=-1)
    app.close()
    return color, depth, elevation, distance, cam


def test_ground_under_every_ray_below_the_horizon(gpu, ctx):
    """A ray going down more steeply than from the camera to the lowest ground at the ring's edge
    meets ground (drawn: depth < 1, no crack); without the ring the same rays see the sky past the
    square's edge. The distances from depth reach far beyond the square."""
    horizon = 60000.0
    color, depth, elevation, distance, cam = render(gpu, horizon)
    lowest = -0.06 * 60.0
    below = elevation < -math.atan((cam.position[1] - lowest) / (horizon - np.abs(cam.position).max()))
    assert below.mean() > 0.3
    assert np.all(depth[below] < 1.0), f"{np.sum(depth[below] >= 1.0)} sky pixels under the horizon"
    # from above a heightfield, looking nearly level, a ray below one that meets ground meets it too:
    # no sky under ground in any column (rows from the bottom, GL order)
    ground = depth < 1.0
    top = ground.shape[0] - 1 - np.argmax(ground[::-1], 0)
    assert all(ground[:top[c], c].all() for c in range(ground.shape[1]) if ground[:, c].any())
    assert 0.02 < (depth >= 1.0).mean() < 0.7                     # the sky above it
    assert distance[depth < 1.0].max() > 2 * 4000.0             # ground well beyond the square
    assert np.all(color[depth < 1.0, 3] == 1.0)
    _, square_depth, _, _, _ = render(gpu, 0.0)
    assert (square_depth[below] >= 1.0).mean() > 0.05


# -- the material --------------------------------------------------------------------------------
def random_inputs(rng, count):
    """Points within 3 km (heights -50..700 m), unit normals up to 80° from vertical, footprints from
    1 cm to 5 km (log-uniform: every octave from sharp to gone), all float32-exact."""
    p = np.stack([rng.uniform(-3000, 3000, count), rng.uniform(-50, 700, count), rng.uniform(-3000, 3000, count)], -1)
    tilt, turn = np.arccos(rng.uniform(math.cos(1.4), 1.0, count)), rng.uniform(0, 2 * math.pi, count)
    n = np.stack([np.sin(tilt) * np.cos(turn), np.cos(tilt), np.sin(tilt) * np.sin(turn)], -1)
    footprint = np.exp(rng.uniform(math.log(0.01), math.log(5000.0), count))
    f32 = lambda a: a.astype(np.float32).astype(np.float64)
    return f32(p), f32(n), f32(footprint)


def test_material_glsl_matches_its_float64_twin(gpu, ctx, rng):
    count = 4096
    p, n, footprint = random_inputs(rng, count)
    relief, snowline, rock_slope = 500.0, float(rng.uniform(0.6, 1.1)), float(rng.uniform(0.1, 0.5))
    data = np.concatenate([np.concatenate([p, footprint[:, None]], -1)[:, None],
                           np.concatenate([n, np.zeros((count, 1))], -1)[:, None]], 1).astype(np.float32)
    program = gpu.program(compute_shader="test/terrain_material_probe.comp")
    source, out = ctx.buffer(data.tobytes()), ctx.buffer(reserve=16 * count)
    try:
        bind_buffers(program, In=source, Out=out)
        write_uniforms(program, count=count, relief=relief, snowline=snowline, rock_slope=rock_slope)
        program.run((count + 63) // 64)
        ctx.memory_barrier()
        got = np.frombuffer(out.read(), np.float32).reshape(count, 4)[:, :3].astype(np.float64)
    finally:
        source.release()
        out.release()
    want = material.albedo(p, n, footprint, relief, snowline, rock_slope)
    # Tolerance: float32 rounds each operation by at most EPS32 relative; an input x passes through a
    # handful of them before the albedo (the division by the cell, the fract, the smoothstep), so the
    # albedo moves by at most |∂albedo/∂x| · |x| · 16 EPS32 per input (the twin's own slopes, central
    # differences), plus the rounding of ~60 operations on values of at most 1 (60 EPS32 each way).
    slope_terms = np.zeros((count, 3))
    columns = [(p, k) for k in range(3)] + [(n, k) for k in range(3)] + [(footprint, None)]
    for array, k in columns:
        value = array[:, k] if k is not None else array
        h = np.maximum(np.abs(value), 1.0) * 1e-6
        hi_, lo_ = array.copy(), array.copy()
        if k is None:
            hi_, lo_ = value + h, value - h
        else:
            hi_[:, k] += h
            lo_[:, k] -= h
        args = [p, n, footprint]
        index = 0 if array is p else 1 if array is n else 2
        up, down = list(args), list(args)
        up[index], down[index] = hi_, lo_
        slope = np.abs(material.albedo(*up, relief, snowline, rock_slope)
                       - material.albedo(*down, relief, snowline, rock_slope)) / (2 * h[:, None])
        slope_terms += slope * np.abs(value)[:, None]
    tolerance = 120 * EPS32 + 16 * EPS32 * slope_terms
    error = np.abs(got - want)
    worst = int(np.argmax((error / tolerance).max(-1)))
    print("material: max |error|", error.max(), "max error / tolerance", (error / tolerance).max(),
          "median tolerance", np.median(tolerance))
    assert np.all(error <= tolerance), (p[worst], n[worst], footprint[worst], got[worst], want[worst])
    assert np.all((want >= 0.0) & (want <= 1.0))


def test_material_has_grass_rock_and_snow_and_fades_its_detail_with_distance(rng):
    up = np.array([0.0, 1.0, 0.0])
    steep = np.array([0.8, 0.6, 0.0])
    xz = rng.uniform(-5000, 5000, (2000, 2))
    low = np.stack([xz[:, 0], np.full(2000, 20.0), xz[:, 1]], -1)
    high = np.stack([xz[:, 0], np.full(2000, 900.0), xz[:, 1]], -1)
    grass = material.albedo(low, up, 1.0, 500.0, 1.0, 0.3)
    rock = material.albedo(low, steep, 1.0, 500.0, 1.0, 0.3)
    snow = material.albedo(high, up, 1.0, 500.0, 1.0, 0.3)
    assert np.all(grass[:, 1] > grass[:, 0]) and np.all(grass[:, 1] > grass[:, 2])        # green
    assert np.all((rock[:, 0] >= rock[:, 1]) & (rock[:, 1] >= rock[:, 2]))               # grey-brown
    assert np.all(snow.min(-1) > 0.6)                                                     # white
    # a fine footprint shows metres of detail, a coarse one keeps only the broad patches
    line = np.stack([np.linspace(0, 64, 4000), np.full(4000, 20.0), np.zeros(4000)], -1)
    near, far = material.albedo(line, up, 0.05, 500.0, 1.0, 0.3), material.albedo(line, up, 50.0, 500.0, 1.0, 0.3)
    assert np.abs(np.diff(near[:, 1])).sum() > 20 * np.abs(np.diff(far[:, 1])).sum()
    for i in range(material.OCTAVES):                                                     # each octave fades out
        cell = material.CELL0 / 2.0 ** i
        assert np.all(material.octave(xz, i, 0.5 * cell) == 0.0)
        assert np.any(material.octave(xz, i, 0.2 * cell) != 0.0)


# -- the mean albedo -----------------------------------------------------------------------------
def test_mean_albedo_is_the_area_weighted_mean_of_the_material(rng):
    terrain = TerrainPlugin(size=256.0, cells=71, relief=30.0)
    mean = terrain.mean_albedo
    assert mean.dtype == np.float64 and mean.shape == (3,)
    # Monte Carlo: random points on the square, weighted by their surface per map area (1 / n_y)
    s = terrain.settings
    count = 200000
    x, z = rng.uniform(-s.size / 2, s.size / 2, (2, count))
    n = terrain.normal_at(x, z)
    step = s.size / min(4 * s.cells, material.MEAN_SAMPLES)
    a = material.albedo(np.stack([x, terrain.height_at(x, z), z], -1), n, step, s.relief, s.snowline, s.rock_slope)
    w = 1.0 / n[:, 1]
    estimate = (a * w[:, None]).sum(0) / w.sum()
    spread = np.sqrt(((a - estimate) ** 2 * (w ** 2)[:, None]).sum(0)) / w.sum()     # its standard error
    np.testing.assert_allclose(mean, estimate, atol=5 * spread.max() + 0.01)
    # flat ground is all grass, high flat ground all snow; a change of settings is seen
    flat = TerrainPlugin(size=256.0, relief=0.0).mean_albedo
    assert flat[1] > flat[0] > flat[2]
    terrain.configure(snowline=-1.0)
    assert terrain.mean_albedo.mean() > mean.mean() + 0.1
    mean[:] = 0.0
    assert terrain.mean_albedo.min() > 0.0                       # a copy: the cache is not the caller's


# -- settings ------------------------------------------------------------------------------------
@pytest.mark.parametrize("field, value, message", [
    ("horizon", -1.0, "TerrainSettings.horizon must be a finite number >= 0.0"),
    ("horizon", math.inf, "TerrainSettings.horizon"),
    ("snowline", math.nan, "TerrainSettings.snowline"),
    ("rock_slope", 1.5, "TerrainSettings.rock_slope must be a finite number >= 0.0 and <= 1.0"),
])
def test_bad_terrain_settings_are_refused_by_name(field, value, message):
    with pytest.raises(ValueError, match=message.replace(".", r"\.")):
        TerrainSettings(**{field: value})
    with pytest.raises(ValueError, match=message.replace(".", r"\.")):
        TerrainPlugin().configure(**{field: value})
