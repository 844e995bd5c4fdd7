"""The diffusion field (plugins/clouds/light/diffusion.py): a P1 solve of the sun's scattered fluence on the
shading grid, per texture set, read by both cloud renderers' light beside the octaves."""
import numpy as np
import pytest

from atmos import DefaultPlugins
from atmos.app import App
from atmos.slicing.texture_sets import make_texture
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds import CloudSettings, CloudsPlugin, read_volume
from atmos.plugins.clouds.light.diffusion import (DIFFUSION, TOLERANCE, DiffusionSolver, apply, diffusion_desc,
                                     diffusion_reference, diffusion_system, field_radiance, field_shape,
                                     read_field, resample, solve_cg)
from atmos.plugins.clouds.light.grid import shading_shape
from atmos.plugins.clouds.light.shear_warp import upload_volume
from tests.test_clouds import params

SUN = np.array([0.3, 0.5, -0.8]) / np.linalg.norm([0.3, 0.5, -0.8])
MEDIUM = (0.02, 1.0, 0.8)          # sigma_t 1/m, albedo, g_mean


def blob(rng, shape):
    x, y, z = np.meshgrid(*[np.linspace(-1, 1, n) if n > 1 else np.zeros(1) for n in shape], indexing="ij")
    return (rng.uniform(0.0, 2.0, shape) * (x * x + y * y + z * z < 1.0)).astype(np.float32)


def sun_transmittance(d, cell=20.0, sigma_t=0.02):
    """A transmittance falling with the density above (any T in [0, 1] will do for the solve)."""
    return np.exp(-sigma_t * cell * np.cumsum(d[:, ::-1].astype(np.float64), 1)[:, ::-1])


def gpu_field(gpu, d, T, scale=1, cell=(20.0, 20.0, 20.0), iterations=400, solver=None, warm=False):
    solver = solver or DiffusionSolver(gpu, d.shape, scale)
    tex, trans = upload_volume(gpu, d), upload_volume(gpu, T)
    target = make_texture(gpu, diffusion_desc(d.shape, scale))
    try:
        solver.solve(tex, trans, target, *MEDIUM, cell, SUN, iterations=iterations, warm=warm)
        return read_field(target), solver.relative_residual()
    finally:
        for t in (tex, trans, target):
            t.release()


def test_the_reference_solves_the_assembled_system():
    rng = np.random.default_rng(4)
    d = blob(rng, (5, 4, 6))
    T = sun_transmittance(d)
    system = diffusion_system(d, (20.0, 15.0, 25.0), *MEDIUM, T, SUN)
    n = d.size
    A = np.stack([apply(system, e.reshape(d.shape)).ravel() for e in np.eye(n)], 1)
    np.testing.assert_allclose(A, A.T, rtol=1e-12, atol=1e-9)                      # symmetric
    assert np.linalg.eigvalsh(A).min() > 0                                          # positive definite
    exact = np.linalg.solve(A, system["rhs"].ravel()).reshape(d.shape)
    phi, _ = solve_cg(system)
    np.testing.assert_allclose(phi, exact, rtol=1e-7, atol=1e-9 * exact.max())
    assert exact.max() > 0.05          # (P1 may dip below 0 behind a dense cell: the renderers clamp)


@pytest.mark.parametrize("case", ["blob", "scale 2", "coarse field", "zero", "one cell", "thin slab", "huge"])
def test_gpu_field_matches_the_float64_reference(gpu, ctx, rng, case):
    shape, scale = {"scale 2": ((20, 10, 16), 2), "coarse field": ((40, 24, 40), 1), "one cell": ((1, 1, 1), 1),
                    "thin slab": ((16, 1, 12), 1)}.get(case, ((18, 9, 14), 1))
    d = {"zero": np.zeros(shape, np.float32), "huge": np.full(shape, 1e30, np.float32)}.get(case)
    d = blob(rng, shape) if d is None else d
    if case == "thin slab":
        d[:] = 1.0
    shading = shading_shape(shape, scale)
    grid = field_shape(shading)                                   # the shading grid, or coarser when large
    assert (grid == shading) == (case != "coarse field")
    T = sun_transmittance(resample(d, shading), 20.0 * scale)
    got, residual = gpu_field(gpu, d, T, scale)
    cell = 20.0 * np.array(shape) / np.array(grid)
    ref = diffusion_reference(resample(d, grid), cell, *MEDIUM, resample(T, grid), SUN)
    assert np.isfinite(got).all()
    assert residual <= TOLERANCE
    top = max(np.abs(ref[..., 0]).max(), 1e-30)
    np.testing.assert_allclose(got, ref, rtol=2 ** -10, atol=2e-3 * top)
    if case in ("zero", "huge"):
        assert np.abs(got).max() < 1e-6, "no source (no density, or T = 0 everywhere): no field"


def test_the_gpu_solve_needs_its_iterations_and_starts_warm_from_the_last(gpu, ctx, rng):
    d = blob(rng, (18, 9, 14))
    T = sun_transmittance(d)
    ref = diffusion_reference(d, 20.0, *MEDIUM, T, SUN)
    few, res_few = gpu_field(gpu, d, T, iterations=5)
    assert res_few > 10 * TOLERANCE and np.abs(few - ref).max() > 0.05 * ref[..., 0].max()
    solver = DiffusionSolver(gpu, d.shape)
    gpu_field(gpu, d, T, solver=solver)
    T2 = sun_transmittance(d, sigma_t=0.021)                                      # the next set: a little different
    cold, res_cold = gpu_field(gpu, d, T2, iterations=12, solver=DiffusionSolver(gpu, d.shape))
    warm, res_warm = gpu_field(gpu, d, T2, iterations=12, solver=solver, warm=True)
    assert res_warm < 0.2 * res_cold


def test_air_around_a_cloud_is_a_vacuum_not_a_conductor():
    """The same cloud solved in a tight box and padded with 6 cells of air each side gets nearly the same
    field: light that leaves a cloud escapes (diffusion.emptiness). With air as a thin medium of huge D
    (transport extinction FLOOR) the padding conducted the lit side's light round to the shadowed side and
    out through the box's far faces: the field moved by 56-58 % (L1), and bench_cloud_light's grazing
    field alone was 45 % off the path tracer's multiple scattering (37 % now)."""
    rng = np.random.default_rng(3)
    for n, dens in ((8, 1.5), (6, 3.0), (10, 1.0)):
        d = (dens * rng.uniform(0.7, 1.3, (n, n, n))).astype(np.float32)
        T = sun_transmittance(d)
        tight = diffusion_reference(d, 20.0, *MEDIUM, T, SUN)[..., 0]
        wide = diffusion_reference(np.pad(d, 6), 20.0, *MEDIUM, np.pad(T, 6, constant_values=1.0), SUN)
        wide = wide[6:-6, 6:-6, 6:-6, 0]
        assert np.abs(wide - tight).sum() / np.abs(tight).sum() < 0.15, (n, dens)


def test_the_field_lights_a_lit_surface_seen_with_the_sun_behind():
    """Against the flux (a view with the sun behind it, cos -1) the truncated P1 radiance phi - 3 g F.d is
    negative at a lit surface, where F runs with the sun's light; the field then gives -cos 2 H phi / 4pi:
    the light a lit surface sends back fills only its outward hemisphere (phi / 2pi) and the phase takes
    its share H of it outward (bench_cloud_light "sun behind": the cumulus was -17.8 % dark with no floor,
    -9.1 % with -cos phi, +2.0 % now). Toward the sun the P1 term is larger and stands. H is checked
    against a quadrature of the lobes."""
    from atmos.phase import Phase, hg
    lobes = (0.85, -0.3, 0.1)
    mu = (np.arange(200000) + 0.5) / 200000                       # midpoint rule over the hemisphere
    quad = 2 * np.pi * np.mean((1 - lobes[2]) * hg(mu, lobes[0]) + lobes[2] * hg(mu, lobes[1]))
    share = Phase(*lobes).hemisphere_share
    assert share == pytest.approx(quad, rel=1e-6) and 0.85 < share < 0.95
    assert Phase(0.0, 0.0, 0.0).hemisphere_share == pytest.approx(0.5)
    assert Phase(1e-5, 0.0, 0.0).hemisphere_share == pytest.approx(0.5, abs=1e-5)
    sun, g, phi = np.array([0.0, 0.6, 0.8]), 0.735, 2.0
    field = np.concatenate([[phi], -0.9 * phi * sun])           # |F| near phi, along the sun's light
    behind, toward, side = -sun, sun, np.array([1.0, 0.0, 0.0])
    assert phi - 3 * g * field[1:] @ behind < 0.0
    got = field_radiance(np.stack([field] * 3), np.stack([behind, toward, side]), lobes, sun)
    want = np.array([2 * share * phi, phi * (1 + 3 * g * 0.9), phi]) / (4 * np.pi)
    np.testing.assert_allclose(got, want, rtol=1e-12)
    half = field_radiance(field, -np.array([0.0, 1.0, 0.0]), lobes, sun)          # cos -0.6
    assert half == pytest.approx(max(phi - 3 * g * field[1:] @ [0.0, -1.0, 0.0], 0.6 * 2 * share * phi) / (4 * np.pi))


def test_an_iteration_is_one_dispatch_and_the_solve_matches_the_twins_iterations(gpu, ctx, rng, monkeypatch):
    """Chronopoulos-Gear: one (indirect) dispatch per iteration; its float32 iterates follow the float64
    twin's: after k iterations the GPU's residual is the twin's within float32's reach."""
    import atmos.plugins.clouds.light.diffusion as diffusion
    d = blob(rng, (12, 6, 10))
    T = sun_transmittance(d)
    calls = []
    real = diffusion.dispatch_indirect
    monkeypatch.setattr(diffusion, "dispatch_indirect", lambda *a: calls.append(a) or real(*a))
    system = diffusion_system(d, 20.0, *MEDIUM, T, SUN)
    for k in (3, 8):
        calls.clear()
        _, residual = gpu_field(gpu, d, T, iterations=k)
        assert len(calls) == k
        x, run = solve_cg(system, iterations=k)
        want = np.sqrt(((system["rhs"] - apply(system, x)) ** 2).sum() / (system["rhs"] ** 2).sum())
        assert run == k and residual == pytest.approx(want, rel=0.02, abs=1e-5), (k, residual, want)


def test_bad_solver_input_is_refused(gpu, ctx):
    solver = DiffusionSolver(gpu, (6, 4, 6))
    tex = upload_volume(gpu, np.ones((6, 4, 6), np.float32))
    with pytest.raises(ValueError, match="sun_dir"):
        solver.begin(tex, tex, *MEDIUM, (20.0, 20.0, 20.0), (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="4-component f2"):
        solver.write(tex)
    with pytest.raises(ValueError, match="transmittance"):
        solver.begin(tex, upload_volume(gpu, np.ones((3, 2, 3), np.float32)), *MEDIUM, (20.0,) * 3, SUN)
    with pytest.raises(ValueError, match="tolerance"):
        DiffusionSolver(gpu, (6, 4, 6), tolerance=0.0)


def test_every_shaded_texture_set_a_renderer_reads_carries_its_field_and_unshaded_ones_none(gpu, ctx):
    weather = params((16, 8, 16))
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False),
                               CloudsPlugin(CloudSettings(smoothing_slices=2, group_size=(8, 8)), weather=weather, seed=3),
                               sprites := CloudRenderPlugin())
    app.startup()
    sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation
    for _ in range(25):
        sim.job.run_step()
    s = sim.settings
    for texture_set in sim.view()[:2]:
        density = read_volume(texture_set["density"])
        assert density.any(), "clouds formed"
        tr = texture_set["transmittance"]
        T = np.frombuffer(tr.read(), np.float16).reshape(tr.size[::-1]).transpose(2, 1, 0).astype(np.float64)
        ref = diffusion_reference(density, s.cell_size, s.sigma_t, s.albedo,
                                  s.phase.mean_cosine, T, sim.sun())
        got = read_field(texture_set[DIFFUSION])
        np.testing.assert_allclose(got, ref, rtol=2 ** -10, atol=2e-3 * ref[..., 0].max())
    sprites.configure(ms_diffusion=0.0)         # no reader: the next steps solve nothing and hold no field
    for _ in range(3):
        sim.job.run_step()
    assert all(DIFFUSION not in texture_set for texture_set in sim.triple.sets)
    sprites.configure(ms_diffusion=0.4)
    for _ in range(2):
        sim.job.run_step()
    assert all(DIFFUSION in texture_set for texture_set in sim.view()[:2])
    app.close()
    app = App(gpu).add_plugins(DefaultPlugins(overlay=False),
                               CloudsPlugin(CloudSettings(shading=False, group_size=(8, 8)), weather=weather),
                               sprites := CloudRenderPlugin(), march := RaymarchCloudsPlugin(enabled=False))
    app.startup()
    sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation
    assert DIFFUSION not in sim.view()[0] and sim.field is None
    for on, off in ((sprites, march), (march, sprites)):          # both draw without a field, weight unused
        off.configure(enabled=False)
        on.configure(enabled=True)
        app.run_frames(2, 1 / 30)
        assert np.isfinite(app.read_linear()).all()
    app.close()


def test_a_scene_no_renderer_reads_the_field_of_solves_none(gpu, ctx):
    """The solve is the chain's costliest task: no cloud renderer, or one disabled, and no step runs it."""
    weather = params((16, 8, 16))
    for extra in ((), (RaymarchCloudsPlugin(enabled=False),), (CloudRenderPlugin(ms_diffusion=0.0),)):
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False), *extra,
                                   CloudsPlugin(CloudSettings(smoothing_slices=2, group_size=(8, 8)), weather=weather))
        app.startup()
        sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation
        app.run_frames(30, 1 / 30)
        assert sim.job.step >= 3
        assert "diffusion" not in sim.job.stats.task_ms, extra
        assert sim.field.solver is None and all(DIFFUSION not in t for t in sim.triple.sets)
        app.close()
    density = np.zeros((8, 4, 8), np.float32)
    density[2:6, 1:3, 2:6] = 1.0
    for weight in (0.0, 0.4):                     # static clouds: the same demand
        app = App(gpu).add_plugins(DefaultPlugins(overlay=False), CloudRenderPlugin(ms_diffusion=weight),
                                   CloudsPlugin(density=density))
        app.run_frames(2, 1 / 30)
        sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation
        assert (DIFFUSION in sim.set) == (weight > 0) and (sim.field.solver is not None) == (weight > 0)
        app.close()


@pytest.mark.parametrize("cls", [CloudRenderPlugin, RaymarchCloudsPlugin])
def test_the_weight_is_checked_in_both_renderers(cls):
    with pytest.raises(ValueError, match="ms_diffusion"):
        cls(ms_diffusion=-0.1)
    with pytest.raises(ValueError, match="ms_diffusion"):
        cls(ms_diffusion=float("nan"))
    assert cls(ms_diffusion=0.0).settings.ms_diffusion == 0.0
