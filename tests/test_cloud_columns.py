"""The light volume's columns (plugins/clouds/light/columns.py): the density integrated straight up and down
per cell of the shading grid, once per texture set, read by both cloud renderers' light."""
import numpy as np
import pytest

from atmos.app import App
from atmos.slicing.texture_sets import make_texture
from atmos.plugins.clouds import CloudSettings, CloudsPlugin, read_volume
from atmos.plugins.clouds.light.columns import COLUMNS, STORE_MAX, ColumnShader, column_desc, column_reference
from atmos.plugins.clouds.light.shear_warp import upload_volume
from tests.test_clouds import params


def read_columns(texture) -> np.ndarray:
    nx, ny, nz = texture.size
    return np.frombuffer(texture.read(), np.float16).reshape(nz, ny, nx, 2).transpose(2, 1, 0, 3).astype(np.float64)


def gpu_columns(gpu, density, scale, **kw):
    tex = upload_volume(gpu, density)
    target = make_texture(gpu, column_desc(density.shape, scale))
    try:
        ColumnShader(gpu, density.shape, scale).run(tex, target, **kw)
        return read_columns(target)
    finally:
        tex.release()
        target.release()


def test_reference_is_the_exact_integral_of_a_linear_density():
    ny = 7
    d = np.broadcast_to(np.arange(ny, dtype=np.float32)[None, :, None], (3, ny, 2))   # rho(y) = y, clamped
    k = np.arange(ny, dtype=np.float64)
    got = column_reference(d)
    np.testing.assert_allclose(got[1, :, 0, 1], k ** 2 / 2, atol=1e-12)
    np.testing.assert_allclose(got[1, :, 0, 0], ((ny - 1) ** 2 - k ** 2) / 2 + (ny - 1) / 2, atol=1e-12)
    coarse = column_reference(d, 2)          # 4 coarse cells over the same box: centres at fine y = 1.75 k + 0.375
    yc = 1.75 * np.arange(4) + 0.375
    np.testing.assert_allclose(coarse[0, :, 0, 1], yc ** 2 / 2, atol=1e-12)
    np.testing.assert_allclose(column_reference(d[:, :1]), 0.0)       # one row of density 0


@pytest.mark.parametrize("shape, scale", [((10, 7, 9), 1), ((10, 7, 9), 2), ((13, 9, 6), 4), ((5, 1, 3), 1)])
def test_gpu_columns_match_the_float64_reference(gpu, ctx, rng, shape, scale):
    d = rng.uniform(0.0, 2.0, shape).astype(np.float32)
    ref = column_reference(d, scale)
    np.testing.assert_allclose(gpu_columns(gpu, d, scale), ref, rtol=2 ** -10, atol=2e-3)


def test_slices_fill_their_z_ranges_and_huge_densities_stay_finite(gpu, ctx, rng):
    d = rng.uniform(0.0, 1.0, (6, 5, 8)).astype(np.float32)
    d[2, :, 3] = 1e30
    tex, target = upload_volume(gpu, d), make_texture(gpu, column_desc(d.shape, 1))
    shader = ColumnShader(gpu, d.shape)
    for z0, z1 in ((0, 3), (3, 3), (3, 8)):
        shader.run(tex, target, z0, z1)
    got = read_columns(target)
    assert np.isfinite(got).all() and got.max() <= STORE_MAX
    np.testing.assert_allclose(got, column_reference(d), rtol=2 ** -10, atol=2e-3)
    with pytest.raises(ValueError, match="z range"):
        shader.run(tex, target, 4, 9)
    with pytest.raises(ValueError, match="2-component f2"):
        shader.run(tex, tex)
    tex.release()
    target.release()


def test_every_texture_set_of_the_simulation_carries_its_columns(gpu, ctx):
    weather = params((16, 8, 16))
    app = App(gpu).add_plugins(CloudsPlugin(CloudSettings(smoothing_slices=2, group_size=(8, 8), shading_scale=2),
                                            weather=weather, seed=3))
    app.startup()
    sim = next(p for p in app.plugins if isinstance(p, CloudsPlugin)).simulation
    for _ in range(25):
        sim.job.run_step()
    a, b, _ = sim.view()
    for s in (a, b):
        density = read_volume(s["density"])
        assert density.any(), "clouds formed"
        np.testing.assert_allclose(read_columns(s[COLUMNS]), column_reference(density, 2), rtol=2 ** -10, atol=2e-3)
    app.close()
