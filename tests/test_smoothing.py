"""Cloud field smoothing and density maps: GPU against the numpy float64 references."""
import numpy as np
import pytest

from atmos.plugins.clouds.automaton import CloudAutomaton
from atmos.plugins.clouds import DensityMaps, Smoother, read_volume, reference, slice_range

LAYOUTS = ("packed", "cell")
NP = {"f2": np.float16, "f4": np.float32}
REL = {"f2": 2.0 ** -10 + 2.0 ** -20, "f4": 1e-6}   # half (llvmpipe truncates); float32 division


@pytest.fixture
def made(ctx):
    """Collects GL objects and atmos objects made by a test and releases them afterwards."""
    objects = []
    yield objects
    for obj in objects:
        obj.release()


def automaton(gpu, made, shape, cld, layout):
    ca = CloudAutomaton(gpu, shape, layout=layout)
    made.append(ca)
    ca.upload(np.zeros(shape, bool), np.zeros(shape, bool), cld)
    return ca


def nan_texture(smoother, made, dtype):
    texture = smoother.create_texture(dtype)
    made.append(texture)
    texture.write(np.full(smoother.shape[::-1], np.nan, NP[dtype]).tobytes())
    return texture


def smooth_gpu(gpu, made, cld, layout="packed", dtype="f2", radius=(1, 1, 1), weights="tent", slices=None):
    """Smooth ``cld`` on the GPU (whole, or in the given (z0, z1) slices) into a NaN-prefilled texture."""
    ca = automaton(gpu, made, cld.shape, cld, layout)
    smoother = Smoother.for_automaton(ca, radius, weights)
    made.append(smoother)
    texture = nan_texture(smoother, made, dtype)
    for z0, z1 in slices or [(0, None)]:
        smoother.run(ca.state_buffer, texture, z0=z0, z1=z1)
    return read_volume(texture), texture, smoother


def assert_matches(got, expected, dtype):
    assert got.dtype == np.float32 and got.shape == expected.shape
    assert not np.isnan(got).any(), f"{np.isnan(got).sum()} texels never written"
    err = np.abs(got - expected)
    assert (err <= REL[dtype] * expected + 1e-12).all(), f"max error {err.max()} at {np.unravel_index(err.argmax(), err.shape)}"
    assert np.array_equal(got > 0, expected > 0), "positivity differs from the reference"


def random_cld(rng, shape):
    return rng.random(shape) < rng.uniform(0.02, 0.5)


# -- smoothing -------------------------------------------------------------------------------------
@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("dtype", ["f2", "f4"])
@pytest.mark.parametrize("shape", [(37, 6, 19), (1, 1, 1), (64, 3, 5), (33, 4, 2)])
def test_smoothing_matches_reference(gpu, ctx, made, rng, layout, dtype, shape):
    cld = random_cld(rng, shape)
    radius = tuple(int(r) for r in rng.integers(0, 4, size=3))
    weights = str(rng.choice(reference.WEIGHTS))
    print("radius", radius, "weights", weights)
    got, _, smoother = smooth_gpu(gpu, made, cld, layout, dtype, radius, weights)
    assert_matches(got, reference.smooth(cld, radius, weights, smoother.min_density(dtype)), dtype)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_smoothing_after_automaton_steps(gpu, ctx, made, rng, layout):
    """The state buffer the automaton leaves after real steps (buffers swap) is read correctly."""
    shape = (45, 5, 11)
    ca = CloudAutomaton(gpu, shape, seed=int(rng.integers(0, 2**32)), layout=layout)
    made.append(ca)
    ca.upload(*(rng.random(shape) < p for p in (0.5, 0.1, 0.3)))
    smoother = Smoother.for_automaton(ca)
    made.append(smoother)
    texture = nan_texture(smoother, made, "f2")
    for _ in range(3):
        ca.step(p_ext=0.1, p_hum=0.05, p_act=0.02, shift=(1, -2))
        smoother.run(ca.state_buffer, texture)
        expected = reference.smooth(ca.download()[2], min_density=smoother.min_density("f2"))
        assert_matches(read_volume(texture), expected, "f2")


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("weights", reference.WEIGHTS)
def test_empty_and_full_volumes(gpu, ctx, made, layout, weights):
    shape = (37, 6, 19)
    empty, _, _ = smooth_gpu(gpu, made, np.zeros(shape, bool), layout, "f4", weights=weights)
    assert (empty == 0).all()
    full, _, _ = smooth_gpu(gpu, made, np.ones(shape, bool), layout, "f2", radius=(2, 1, 1), weights=weights)
    assert (full[2:-2, 1:-1, 1:-1] == 1.0).all(), "a full neighbourhood must give exactly 1.0"
    # no renormalization at the borders: outside cells count as 0
    assert (full[0] < 1).all() and (full[:, 0] < 1).all() and (full[:, :, -1] < 1).all()
    assert_matches(full, reference.smooth(np.ones(shape, bool), (2, 1, 1), weights, 2.0 ** -14), "f2")


@pytest.mark.parametrize("layout", LAYOUTS)
def test_tiny_densities_stay_positive_in_r16f(gpu, ctx, made, rng, layout):
    """Radius 8 tent: a lone cell's far corner weighs 1/81**3, below half precision; it is floored."""
    shape = (40, 17, 18)
    cld = rng.random(shape) < 0.0005
    cld[int(rng.integers(0, 40)), 8, 9] = True
    got, _, smoother = smooth_gpu(gpu, made, cld, layout, "f2", radius=8)
    expected = reference.smooth(cld, 8, "tent", smoother.min_density("f2"))
    assert_matches(got, expected, "f2")
    assert got[got > 0].min() >= 2.0 ** -14
    assert (reference.smooth(cld, 8) > 0).sum() == (got > 0).sum()


def test_radius_zero_is_the_cld_field(gpu, ctx, made, rng):
    cld = random_cld(rng, (37, 6, 19))
    got, _, _ = smooth_gpu(gpu, made, cld, "packed", "f2", radius=0)
    assert np.array_equal(got, cld.astype(np.float32))


@pytest.mark.parametrize("layout", LAYOUTS)
def test_sliced_smoothing_equals_whole(gpu, ctx, made, rng, layout):
    shape = (37, 6, 19)
    cld = random_cld(rng, shape)
    whole, _, _ = smooth_gpu(gpu, made, cld, layout)
    cuts = np.sort(rng.choice(np.arange(1, 19), size=4, replace=False))
    slices = list(zip([0, *cuts], [*cuts, 19])) + [(5, 5)]
    sliced, _, _ = smooth_gpu(gpu, made, cld, layout, slices=slices)
    assert np.array_equal(sliced, whole)
    one_layer, _, _ = smooth_gpu(gpu, made, cld, layout, slices=[slice_range(19, i, 19) for i in range(19)])
    assert np.array_equal(one_layer, whole)


def test_slice_writes_only_its_layers(gpu, ctx, made, rng):
    cld = random_cld(rng, (20, 3, 9))
    got, _, _ = smooth_gpu(gpu, made, cld, slices=[(2, 5)])
    assert not np.isnan(got[:, :, 2:5]).any()
    assert np.isnan(got[:, :, :2]).all() and np.isnan(got[:, :, 5:]).all()


def test_slice_range_covers_everything():
    for n, count in ((19, 4), (32, 32), (3, 5), (256, 7)):
        pieces = [slice_range(n, i, count) for i in range(count)]
        assert pieces[0][0] == 0 and pieces[-1][1] == n
        assert all(a[1] == b[0] for a, b in zip(pieces, pieces[1:]))
    with pytest.raises(ValueError, match="slice index"):
        slice_range(10, 3, 3)


def test_smoother_rejects_bad_parameters(gpu, ctx):
    too_long = ctx.info["GL_MAX_3D_TEXTURE_SIZE"] + 1          # the context's limit (2048 on Mesa, 16384 on NVIDIA)
    for kwargs, match in [({"shape": (0, 1, 1)}, "shape"), ({"shape": (2, 2)}, "shape"),
                          ({"radius": 9}, r"radius .*\[0, 8\]"), ({"radius": (1, -1, 1)}, "radius"),
                          ({"radius": 1.5}, "radius"), ({"weights": "gauss"}, "weights .*tent"),
                          ({"layout": "bits"}, "layout .*packed"),
                          ({"shape": (too_long, 1, 1)}, rf"too big .*at most {too_long - 1} per axis")]:
        args = {"shape": (4, 4, 4), **kwargs}
        with pytest.raises(ValueError, match=match):
            Smoother(gpu, **args)
    with pytest.raises(ValueError, match="GpuContext"):
        Smoother(object(), (4, 4, 4))
    with pytest.raises(ValueError, match="GpuContext"):
        DensityMaps(gpu.ctx, (4, 4, 4))


def test_run_rejects_bad_input_and_changes_nothing(gpu, ctx, made, rng):
    shape = (37, 6, 19)
    ca = automaton(gpu, made, shape, random_cld(rng, shape), "packed")
    smoother = Smoother.for_automaton(ca)
    made.append(smoother)
    texture = nan_texture(smoother, made, "f2")
    small = ctx.buffer(reserve=16)
    wrong_size = ctx.texture3d((37, 6, 18), 1, dtype="f2")
    wrong_dtype = ctx.texture3d(shape, 1, dtype="f1")
    two = ctx.texture3d(shape, 2, dtype="f2")
    made += [small, wrong_size, wrong_dtype, two]
    cases = [((small, texture), {}, "state_buffer .*bytes"), ((texture, texture), {}, "state_buffer"),
             ((ca.state_buffer, wrong_size), {}, r"Texture3D of size \(37, 6, 19\)"),
             ((ca.state_buffer, wrong_dtype), {}, "dtype 'f2' or 'f4'"),
             ((ca.state_buffer, two), {}, "1 component"),
             ((ca.state_buffer, texture), {"z0": 5, "z1": 4}, "z0 <= z1 <= 19"),
             ((ca.state_buffer, texture), {"z1": 20}, "z range"),
             ((ca.state_buffer, texture), {"z0": 1.0}, "z range")]
    for args, kwargs, match in cases:
        with pytest.raises(ValueError, match=match):
            smoother.run(*args, **kwargs)
    assert np.isnan(read_volume(texture)).all(), "a rejected run must not write anything"


# -- density maps ----------------------------------------------------------------------------------
def nan_maps(gpu, made, shape, band_height, group_size):
    maps = DensityMaps(gpu, shape, band_height, group_size)
    made.append(maps)
    for texture in (maps.sums, maps.max_maps):
        texture.write(np.full(texture.size[::-1], np.nan, np.float32).tobytes())
    return maps


def assert_maps(maps, density_gpu, density_ref):
    """Sums and max maps equal the reference of the GPU density; segments > 0 iff the exact
    reference density has any density there."""
    sums, maxes = maps.read_sums(), maps.read_max_maps()
    exp_sums, exp_max = reference.density_maps(density_gpu, maps.band_height, maps.group_size)
    assert sums.shape == exp_sums.shape and maxes.shape == exp_max.shape == (1 + maps.bands, *maps.grid)
    assert not np.isnan(sums).any() and not np.isnan(maxes).any(), "texels never written"
    tol = 1e-6 * maps.shape[1] * max(1.0, float(exp_sums.max()))
    assert np.abs(sums - exp_sums).max() <= tol
    assert np.abs(maxes - exp_max).max() <= tol
    _, ref_max = reference.density_maps(density_ref, maps.band_height, maps.group_size)
    assert np.array_equal(maxes > 0, ref_max > 0), "empty-space skipping would drop density"


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("shape,band_height,group_size", [
    ((37, 6, 19), 4, (5, 7)), ((37, 6, 19), 4, (32, 32)), ((1, 1, 1), 4, (32, 32)),
    ((70, 9, 33), 2, (3, 32)), ((37, 6, 19), 1, 1), ((37, 6, 19), 7, (37, 19))])
def test_density_maps_match_reference(gpu, ctx, made, rng, layout, shape, band_height, group_size):
    cld = rng.random(shape) < rng.uniform(0.0005, 0.05)   # sparse: many empty segments
    density, texture, smoother = smooth_gpu(gpu, made, cld, layout, str(rng.choice(["f2", "f4"])))
    maps = nan_maps(gpu, made, shape, band_height, group_size)
    maps.run(texture)
    assert_maps(maps, density, reference.smooth(cld))


@pytest.mark.parametrize("fill", [False, True])
def test_density_maps_of_empty_and_full_volumes(gpu, ctx, made, fill):
    shape = (37, 6, 19)
    cld = np.full(shape, fill)
    density, texture, _ = smooth_gpu(gpu, made, cld)
    maps = nan_maps(gpu, made, shape, 4, (8, 8))
    maps.run(texture)
    assert_maps(maps, density, reference.smooth(cld))
    assert (maps.read_max_maps() > 0).all() == fill and (maps.read_max_maps() == 0).all() != fill


def test_sliced_pipeline_equals_whole(gpu, ctx, made, rng):
    """Smoothing and density maps interleaved slice by slice, as a frame scheduler runs them."""
    shape = (37, 6, 19)
    cld = rng.random(shape) < 0.02
    density, texture, _ = smooth_gpu(gpu, made, cld)
    whole = nan_maps(gpu, made, shape, 4, (5, 7))
    whole.run(texture)
    ca = automaton(gpu, made, shape, cld, "packed")
    smoother = Smoother.for_automaton(ca)
    made.append(smoother)
    sliced_tex = nan_texture(smoother, made, "f2")
    sliced = nan_maps(gpu, made, shape, 4, (5, 7))
    count = int(rng.integers(2, 20))
    for i in range(count):
        z0, z1 = slice_range(shape[2], i, count)
        smoother.run(ca.state_buffer, sliced_tex, z0, z1)
        sliced.run(sliced_tex, z0, z1)
    assert np.array_equal(read_volume(sliced_tex), density)
    assert np.array_equal(sliced.read_sums(), whole.read_sums())
    assert np.array_equal(sliced.read_max_maps(), whole.read_max_maps())
    assert_maps(sliced, density, reference.smooth(cld))


def test_density_maps_reject_bad_input(gpu, ctx, made):
    layers, side = ctx.info["GL_MAX_ARRAY_TEXTURE_LAYERS"], ctx.info["GL_MAX_TEXTURE_SIZE"]   # the context's limits
    for kwargs, match in [({"band_height": 0}, "band_height"), ({"band_height": 2.0}, "band_height"),
                          ({"group_size": (0, 3)}, "group_size"), ({"group_size": (1, 2, 3)}, "group_size"),
                          ({"shape": (3, 0, 3)}, "shape"),
                          ({"shape": (32, layers, 32), "band_height": 1}, "too big .*GL_MAX_ARRAY_TEXTURE_LAYERS"),
                          ({"shape": (side + 1, 1, 1)}, "too big .*GL_MAX_TEXTURE_SIZE")]:
        with pytest.raises(ValueError, match=match):
            DensityMaps(gpu, **{"shape": (8, 4, 8), **kwargs})
    maps = nan_maps(gpu, made, (8, 4, 8), 4, 4)
    wrong = ctx.texture3d((8, 4, 7), 1, dtype="f2")
    made.append(wrong)
    with pytest.raises(ValueError, match=r"density must be .*\(8, 4, 8\)"):
        maps.run(wrong)
    good = ctx.texture3d((8, 4, 8), 1, dtype="f2")
    made.append(good)
    with pytest.raises(ValueError, match="z range"):
        maps.run(good, 0, 9)
    assert np.isnan(maps.read_sums()).all() and np.isnan(maps.read_max_maps()).all()


def test_smoothers_and_maps_of_other_shapes_share_the_context_programs(gpu, ctx, made, rng):
    """Two pipelines of different shapes and radii, run slice by slice in turn: each writes its own
    uniforms on the shared gpu.program programs, so each still equals its reference."""
    runs = []
    for shape, radius, groups in (((37, 6, 19), (1, 2, 1), (5, 7)), ((20, 9, 33), (3, 0, 2), (32, 4))):
        cld = random_cld(rng, shape)
        ca = automaton(gpu, made, shape, cld, "packed")
        smoother = Smoother.for_automaton(ca, radius)
        made.append(smoother)
        texture, maps = nan_texture(smoother, made, "f4"), nan_maps(gpu, made, shape, 2, groups)
        runs.append((cld, radius, ca, smoother, texture, maps))
    for i in range(4):
        for cld, radius, ca, smoother, texture, maps in runs:
            z0, z1 = slice_range(cld.shape[2], i, 4)
            smoother.run(ca.state_buffer, texture, z0, z1)
            maps.run(texture, z0, z1)
    for cld, radius, ca, smoother, texture, maps in runs:
        expected = reference.smooth(cld, radius, "tent", smoother.min_density("f4"))
        assert_matches(read_volume(texture), expected, "f4")
        assert_maps(maps, read_volume(texture), expected)
    assert {"clouds/simulation/smooth.comp", "clouds/simulation/density_sums.comp", "clouds/simulation/density_max.comp"} <= gpu.compiled_files
