"""Cloud automaton: GPU (packed and cell layouts) against the numpy reference, bit for bit."""
import numpy as np
import pytest

from atmos.hashing import hash4, hash_counter, lowbias32, stream_key
from atmos.plugins.clouds.automaton import CloudAutomaton, reference
from atmos.gpu.uniforms import bind_buffers

LAYOUTS = ("packed", "cell")


@pytest.fixture
def make(gpu, ctx):
    made = []

    def factory(shape, seed=0, layout="packed"):
        ca = CloudAutomaton(gpu, shape, seed=seed, layout=layout)
        made.append(ca)
        return ca

    yield factory
    for ca in made:
        ca.release()


def random_state(rng, shape, p=(0.4, 0.05, 0.2)):
    return tuple(rng.random(shape) < q for q in p)


def run_both(make, rng, shape, steps, kwargs_for_step, layouts=LAYOUTS, state=None):
    """Run the GPU automaton(s) and the reference; assert equality after every step."""
    seed = int(rng.integers(0, 2**32))
    state = random_state(rng, shape) if state is None else state
    autos = [make(shape, seed=seed, layout=layout) for layout in layouts]
    for ca in autos:
        ca.upload(*state)
    expected = state
    for i in range(steps):
        kwargs = kwargs_for_step(i)
        expected = reference.step(*expected, seed=seed, step=i, **kwargs)
        for ca in autos:
            ca.step(**kwargs)
            got = ca.download()
            for name, g, e in zip(("hum", "act", "cld"), got, expected):
                assert g.dtype == bool and g.shape == shape
                assert np.array_equal(g, e), f"{ca.layout}: {name} differs at step {i} ({(g != e).sum()} cells)"
    return expected, autos


# -- hash ------------------------------------------------------------------------------------------
def test_hash_glsl_matches_numpy(gpu, ctx, rng):
    n = 4096
    inputs = rng.integers(0, 2**32, size=(n, 4), dtype=np.uint64).astype(np.uint32)
    inputs[:16] = 0
    inputs[16:32, 0] = 0xFFFFFFFF
    inputs[:, 3] &= np.uint32(0xFFFF)
    prog = gpu.program(compute_shader="clouds/automaton/hash_check.comp")
    src = ctx.buffer(inputs.astype("<u4").tobytes())
    dst = ctx.buffer(reserve=8 * n)
    try:
        bind_buffers(prog, Inputs=src, Outputs=dst)
        prog["u_count"].value = n
        prog.run(-(-n // 64))
        ctx.memory_barrier()
        out = np.frombuffer(dst.read(), dtype="<u4").reshape(n, 2)
    finally:
        src.release()
        dst.release()
    c, seed, step, stream = inputs.T
    assert np.array_equal(out[:, 0], lowbias32(c))
    assert np.array_equal(out[:, 1], hash4(c, seed, step, stream))
    ka, kb = stream_key(seed, step, stream >> np.uint32(8), stream & np.uint32(255))
    assert np.array_equal(out[:, 1], hash_counter(c, ka, kb))


def test_lowbias32_is_uint32_with_wraparound():
    x = np.array([0, 1, 2**31, 2**32 - 1], dtype=np.uint32)
    y = lowbias32(x)
    assert y.dtype == np.uint32 and y[0] == 0 and len(set(y.tolist())) == 4
    # python ints (even negative ones) wrap like GLSL uint()
    assert lowbias32(-1) == lowbias32(np.uint32(0xFFFFFFFF))
    # a bijection: no collisions on a block of consecutive counters
    assert len(np.unique(lowbias32(np.arange(1 << 16, dtype=np.uint32)))) == 1 << 16


def binomial_ok(k, n, p, sigmas=5.0):
    sd = np.sqrt(n * p * (1 - p)) + 1.0
    return abs(k - n * p) <= sigmas * sd


@pytest.mark.parametrize("p", [0.001, 0.05, 0.3, 0.5, 0.77, 0.999])
def test_bernoulli_rate_matches_p(rng, p):
    shape = (96, 16, 40)
    seed = int(rng.integers(0, 2**32))
    hits = reference.bernoulli(p, shape, seed, int(rng.integers(0, 1000)), int(rng.integers(0, 3)))
    q = reference.threshold(p) / 2.0**16   # the exact event probability
    assert abs(q - p) <= 2.0**-17
    assert binomial_ok(hits.sum(), hits.size, q), (hits.mean(), p)


def test_random_numbers_uniform_and_independent(rng):
    shape = (128, 16, 32)
    seed = int(rng.integers(0, 2**32))
    u = reference.random_numbers(shape, seed, 7, 1).astype(np.float64) / 2**16
    n = u.size
    counts = np.histogram(u, bins=32, range=(0, 1))[0]
    chi2 = ((counts - n / 32) ** 2 / (n / 32)).sum()
    assert chi2 < 31 + 6 * np.sqrt(62), chi2          # 31 dof, ~6 sigma

    def corr(a, b):
        a, b = a.ravel() - a.mean(), b.ravel() - b.mean()
        return (a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum())

    bound = 5 / np.sqrt(n)
    assert abs(corr(u[1:], u[:-1])) < bound * 1.01                        # x neighbours (same word)
    assert abs(corr(u[32:], u[:-32])) < bound * 1.01                      # x: next word, same bit
    assert abs(corr(u[:, 1:], u[:, :-1])) < bound * 1.01                  # y neighbours
    assert abs(corr(u[:, :, 1:], u[:, :, :-1])) < bound * 1.01            # z neighbours
    nxt = reference.random_numbers(shape, seed, 8, 1).astype(np.float64)
    assert abs(corr(u, nxt)) < bound                                      # consecutive steps
    other = reference.random_numbers(shape, seed, 7, 2).astype(np.float64)
    assert abs(corr(u, other)) < bound                                    # different rules
    reseed = reference.random_numbers(shape, (seed + 1) % 2**32, 7, 1).astype(np.float64)
    assert abs(corr(u, reseed)) < bound                                   # neighbouring seeds
    # Bernoulli bits of neighbouring cells and consecutive steps: joint rate is p*p
    b0 = reference.bernoulli(0.3, shape, seed, 3, 0)
    b1 = reference.bernoulli(0.3, shape, seed, 4, 0)
    q = (reference.threshold(0.3) / 2**16) ** 2
    assert binomial_ok((b0[1:] & b0[:-1]).sum(), b0[1:].size, q)
    assert binomial_ok((b0 & b1).sum(), b0.size, q)


def test_gpu_bernoulli_rate(make, rng):
    shape = (64, 8, 32)
    ca = make(shape, seed=int(rng.integers(0, 2**32)))
    empty = np.zeros(shape, bool)
    for p in (0.02, 0.5):
        ca.upload(hum=empty, act=empty, cld=empty)
        ca.step(p_hum=p)
        hum, act, cld = ca.download()
        assert binomial_ok(hum.sum(), hum.size, p)
        assert not act.any() and not cld.any()


# -- bit for bit against the reference -------------------------------------------------------------
@pytest.mark.parametrize("shape", [(70, 9, 11), (33, 5, 7), (1, 1, 1), (32, 4, 3), (5, 1, 40)])
def test_growth_only(make, rng, shape):
    run_both(make, rng, shape, 4, lambda i: {})


def test_growth_neighbourhood(make, ctx):
    """A single active humid cell activates exactly the eq. 2.4 neighbourhood (mirrored)."""
    shape = (9, 9, 9)
    hum = np.ones(shape, bool)
    act = np.zeros(shape, bool)
    act[4, 4, 4] = True
    for layout in LAYOUTS:
        ca = make(shape, layout=layout)
        ca.upload(hum=hum, act=act, cld=np.zeros(shape, bool))
        ca.step()
        h, a, c = ca.download()
        got = {tuple(int(v) - 4 for v in idx) for idx in zip(*np.nonzero(a))}
        # a cell at offset o activates when act(cell + n) for n in the neighbourhood: o = -n
        assert got == {tuple(-d for d in n) for n in reference.NEIGHBOURS}
        assert (0, 2, 0) in got and (0, -2, 0) not in got    # grows upward (+y) only by 2
        assert c[4, 4, 4] and c.sum() == 1 and not h[4, 4, 4] and h.sum() == hum.size - 1


@pytest.mark.parametrize("shape", [(70, 9, 11), (33, 5, 7), (1, 1, 1)])
def test_stochastic_scalar(make, rng, shape):
    run_both(make, rng, shape, 4, lambda i: {"p_ext": 0.2, "p_hum": 0.1 * (i + 1), "p_act": 0.03})


@pytest.mark.parametrize("shape", [(70, 9, 11), (33, 5, 7), (1, 1, 1)])
def test_stochastic_arrays(make, rng, shape):
    arrays = [rng.random(shape).astype(np.float32) * s for s in (0.5, 0.4, 0.1)]
    arrays[1][rng.random(shape) < 0.1] = 1.0
    arrays[2][rng.random(shape) < 0.3] = 0.0
    other = rng.random(shape).astype(np.float32)

    def kwargs(i):
        # steps 0-1 reuse the same objects (cached), step 2 a new p_hum array, step 3 mixes a scalar
        return {"p_ext": arrays[0], "p_hum": other if i >= 2 else arrays[1],
                "p_act": 0.25 if i == 3 else arrays[2]}
    run_both(make, rng, shape, 4, kwargs)


def test_mixed_everything_packed_equals_cell(make, rng):
    shape = (75, 12, 20)
    p_ext = (rng.random(shape) * 0.3).astype(np.float32)
    per_layer = rng.integers(-3, 4, size=(shape[1], 2))

    def kwargs(i):
        return {"p_ext": p_ext, "p_hum": 0.15, "p_act": 0.01, "shift": per_layer if i % 2 else (i, -1)}
    run_both(make, rng, shape, 8, kwargs)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_automata_of_different_shapes_share_the_context_programs(gpu, make, rng, layout):
    """Programs come from gpu.program (one per file): automata of other shapes stepped in between
    (their size uniforms on the same program) change nothing; release leaves the programs cached."""
    shapes = [(70, 9, 11), (5, 3, 40), (33, 5, 7)]
    autos = [make(shape, seed=7 + i, layout=layout) for i, shape in enumerate(shapes)]
    expected = [random_state(rng, shape) for shape in shapes]
    probs = [(rng.random(shape) * 0.3).astype(np.float32) for shape in shapes]
    for ca, state in zip(autos, expected):
        ca.upload(*state)
    for step in range(3):
        for i, ca in enumerate(autos):
            kwargs = {"p_ext": probs[i], "p_hum": 0.1, "p_act": 0.02, "shift": (step + 1, -1)}
            expected[i] = reference.step(*expected[i], seed=7 + i, step=step, **kwargs)
            ca.step(**kwargs)
    for ca, e in zip(autos, expected):
        assert all(np.array_equal(g, x) for g, x in zip(ca.download(), e))
    prefix = "clouds/automaton/packed_" if layout == "packed" else "clouds/automaton/cell_"
    assert prefix + "step.comp" in gpu.compiled_files
    programs = len(gpu._programs)
    autos[0].release()
    again = make(shapes[0], layout=layout)
    assert len(gpu._programs) == programs and again._prog_step is autos[1]._prog_step


@pytest.mark.parametrize("shift", [(1, 0), (0, 1), (-1, -1), (5, -3), (31, 2), (32, 0), (-33, 4),
                                   (40, 0), (-70, 0), (0, -11), (2, 11)])
def test_advection_single_pair(make, rng, shift):
    run_both(make, rng, (70, 6, 11), 2, lambda i: {"shift": shift})


def test_advection_per_layer(make, rng):
    shape = (65, 7, 13)
    shifts = rng.integers(-40, 41, size=(shape[1], 2))
    shifts[0] = (0, 0)
    run_both(make, rng, shape, 3, lambda i: {"shift": shifts, "p_hum": 0.1})


def test_advection_moves_contents(make):
    shape = (40, 2, 6)
    hum = np.zeros(shape, bool)
    hum[3, 0, 1] = hum[3, 1, 1] = True
    for layout in LAYOUTS:
        ca = make(shape, layout=layout)
        ca.upload(hum=hum, act=np.zeros(shape, bool), cld=np.zeros(shape, bool))
        ca.step(shift=np.array([[30, 2], [-3, -1]]))
        h, _, _ = ca.download()
        assert h[33, 0, 3] and h[0, 1, 0] and h.sum() == 2


@pytest.mark.parametrize("shift", [(70, 0), (-71, 0), (0, 11), (0, -500), (10**9, 0), (-(2**40), 3)])
def test_advection_beyond_volume_empties(make, rng, shift):
    (hum, act, cld), _ = run_both(make, rng, (70, 4, 11), 1, lambda i: {"shift": shift, "p_hum": 0.5})
    assert not hum.any() and not act.any() and not cld.any()


# -- extremes --------------------------------------------------------------------------------------
@pytest.mark.parametrize("layout", LAYOUTS)
def test_probability_one_and_zero(make, rng, layout):
    shape = (33, 5, 7)
    state = random_state(rng, shape)
    ca = make(shape, layout=layout)
    ones = np.ones(shape, np.float32)
    zeros = np.zeros(shape, np.float32)
    for p_one, p_zero in ((1.0, 0.0), (ones, zeros)):
        ca.upload(*state)
        ca.step(p_ext=p_one, p_hum=p_one, p_act=p_one)
        hum, act, cld = ca.download()
        assert hum.all() and act.all() and not cld.any()
        ca.upload(*state)
        ca.step(p_ext=p_zero, p_hum=p_zero, p_act=p_zero)
        assert all(np.array_equal(g, e) for g, e in zip(ca.download(), reference.growth(*state)))


def test_tiny_probability_rounds_to_zero_identically(make, rng):
    # p below 2**-17 has threshold 0: never fires, on both sides
    run_both(make, rng, (40, 3, 5), 2, lambda i: {"p_hum": 2.0**-18, "p_act": 2.0**-16})


# -- API -------------------------------------------------------------------------------------------
def test_attributes_and_gpu_state(make, rng):
    shape = (33, 5, 7)
    state = random_state(rng, shape)
    for layout in LAYOUTS:
        ca = make(shape, seed=3, layout=layout)
        assert ca.shape == shape and ca.layout == layout and ca.step_count == 0
        ca.upload(*state)
        ca.step(p_hum=0.1)
        ca.step(shift=(1, 1))
        assert ca.step_count == 2
        hum, act, cld = ca.download()
        raw = np.frombuffer(ca.state_buffer.read(), dtype="<u4")
        if layout == "packed":
            n = ca.words_x * shape[1] * shape[2]
            assert raw.size == 3 * n
            words = raw.reshape(3, shape[2], shape[1], ca.words_x)
            assert np.array_equal(words[1, 0, 0, 0] & 1, np.uint32(act[0, 0, 0]))
            assert not (words[:, :, :, -1] >> np.uint32(shape[0] % 32)).any()   # padding bits 0
        else:
            cells = raw.reshape(shape[2], shape[1], shape[0]).transpose(2, 1, 0)
            assert np.array_equal((cells & 4) != 0, cld) and np.array_equal((cells & 1) != 0, hum)
        assert repr(ca).startswith("CloudAutomaton(")


def test_probability_cache_by_identity_and_forget(make, rng):
    shape = (40, 3, 5)
    p = np.zeros(shape, np.float32)
    empty = np.zeros(shape, bool)
    ca = make(shape)
    ca.upload(hum=empty, act=empty, cld=empty)
    ca.step(p_hum=p)
    p[:] = 1.0                      # modified in place: the cached upload is still used ...
    ca.step(p_hum=p)
    assert not ca.download()[0].any()
    ca.forget_probabilities()       # ... until the cache is dropped
    ca.step(p_hum=p)
    assert ca.download()[0].all()


@pytest.mark.parametrize("kwargs, words", [
    ({"p_ext": -0.1}, ["p_ext", "[0, 1]"]),
    ({"p_hum": 1.5}, ["p_hum", "[0, 1]"]),
    ({"p_act": float("nan")}, ["p_act", "[0, 1]"]),
    ({"p_act": float("inf")}, ["p_act"]),
    ({"p_ext": "0.5"}, ["p_ext", "float"]),
    ({"p_ext": True}, ["p_ext", "float"]),
    ({"p_ext": None}, ["p_ext"]),
    ({"p_hum": np.zeros((4, 3, 5), np.float32)}, ["p_hum", "shape"]),
    ({"p_hum": np.zeros((5, 3, 4), np.float32)}, ["p_hum", "shape"]),
    ({"p_hum": np.zeros((4, 3, 4), np.float64)}, ["p_hum", "float32"]),
    ({"p_hum": np.zeros((4, 3, 4), np.int32)}, ["p_hum", "float32"]),
    ({"p_act": np.full((4, 3, 4), 1.01, np.float32)}, ["p_act", "[0, 1]"]),
    ({"p_act": np.full((4, 3, 4), np.nan, np.float32)}, ["p_act", "NaN"]),
    ({"shift": (1.5, 0)}, ["shift", "int"]),
    ({"shift": (1, 2, 3)}, ["shift", "(3, 2)"]),
    ({"shift": np.zeros((4, 2), int)}, ["shift", "(3, 2)"]),
    ({"shift": (True, False)}, ["shift", "int"]),
    ({"shift": "ab"}, ["shift"]),
])
def test_bad_step_inputs(make, rng, kwargs, words):
    shape = (4, 3, 4)
    ca = make(shape)
    state = random_state(rng, shape)
    ca.upload(*state)
    good = {"p_ext": np.full(shape, 0.5, np.float32), "p_hum": 0.5, "p_act": 0.5, "shift": (1, 0)}
    with pytest.raises(ValueError) as info:
        ca.step(**{**good, **kwargs})
    for word in words:
        assert word in str(info.value), str(info.value)
    # nothing half-applied
    assert ca.step_count == 0
    assert all(np.array_equal(g, e) for g, e in zip(ca.download(), state))


def test_bad_upload_and_constructor_inputs(gpu, make):
    shape = (4, 3, 4)
    ca = make(shape)
    good = np.zeros(shape, bool)
    with pytest.raises(ValueError, match="hum.*bool"):
        ca.upload(hum=good.astype(np.uint8), act=good, cld=good)
    with pytest.raises(ValueError, match=r"cld.*shape \(4, 3, 4\)"):
        ca.upload(hum=good, act=good, cld=np.zeros((4, 4, 3), bool))
    with pytest.raises(ValueError, match="act.*bool"):
        ca.upload(hum=good, act=[[[True]]], cld=good)
    with pytest.raises(ValueError, match="layout"):
        CloudAutomaton(gpu, shape, layout="texture")
    with pytest.raises(ValueError, match="seed"):
        CloudAutomaton(gpu, shape, seed=-1)
    with pytest.raises(ValueError, match="seed"):
        CloudAutomaton(gpu, shape, seed=2**32)
    for bad in [(4, 3), (0, 3, 4), (4.0, 3, 4), (4, -1, 4), None, (True, 3, 4)]:
        with pytest.raises(ValueError, match="shape"):
            CloudAutomaton(gpu, bad)
    with pytest.raises(ValueError, match="gpu"):
        CloudAutomaton(None, shape)
    with pytest.raises(ValueError, match="GpuContext"):
        CloudAutomaton(gpu.ctx, shape)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_shape_too_big_for_gpu(gpu, ctx, layout):
    limit = int(ctx.info["GL_MAX_SHADER_STORAGE_BLOCK_SIZE"])
    side = int(np.ceil((limit / 4) ** (1 / 3))) + 64
    for shape in [(side, side, side), (2**20, 2**12, 2**12)]:
        with pytest.raises(ValueError, match="too big.*GL_MAX_SHADER_STORAGE_BLOCK_SIZE"):
            CloudAutomaton(gpu, shape, layout=layout)


def test_more_layers_than_the_advection_takes_is_a_clear_error(gpu, ctx):
    from atmos.plugins.clouds.automaton.automaton import MAX_LAYERS
    with pytest.raises(ValueError, match=rf"has {MAX_LAYERS + 1} layers; the automaton advects at most {MAX_LAYERS}"):
        CloudAutomaton(gpu, (4, MAX_LAYERS + 1, 4))
    CloudAutomaton(gpu, (4, MAX_LAYERS, 4)).release()


def test_release(make):
    ca = make((4, 3, 4))
    ca.release()
    ca.release()
    with pytest.raises(RuntimeError, match="released"):
        ca.step()


@pytest.mark.parametrize("layout", ["packed", "cell"])
def test_step_with_region_texture_equals_step_with_arrays(gpu, ctx, rng, layout):
    """The weather region's probability texture drives a step on the GPU exactly like float32 arrays."""
    from atmos.plugins.clouds.weather import RegionVolume, WeatherSettings
    shape = (37, 6, 11)
    params = WeatherSettings(hum_scale=0.3, act_scale=0.05, ext_scale=0.2, volume_shape=shape)
    ellipsoids = np.zeros((6, 8), np.float32)
    ellipsoids[:, :3] = rng.uniform(0, 1, (6, 3)) * shape
    ellipsoids[:, 3] = rng.uniform(0, 6.28, 6)
    ellipsoids[:, 4:7] = rng.uniform(2, 8, (6, 3))
    region = RegionVolume(gpu, shape)
    region.render(ellipsoids)
    texture = region.probabilities(params)
    p_hum, p_act, p_ext = region.download_probabilities()
    state = [rng.random(shape) < 0.3 for _ in range(3)]
    a, b = CloudAutomaton(gpu, shape, seed=5, layout=layout), CloudAutomaton(gpu, shape, seed=5, layout=layout)
    for ca in (a, b):
        ca.upload(*state)
    for _ in range(3):
        a.step_with_texture(texture, shift=(1, -1))
        b.step(p_ext=p_ext, p_hum=p_hum, p_act=p_act, shift=(1, -1))
    for x, y in zip(a.download(), b.download()):
        assert np.array_equal(x, y)
    bad = ctx.texture3d((2, 2, 2), 4)
    with pytest.raises(ValueError, match="Texture3D of size"):
        a.step_with_texture(bad)
    for obj in (a, b, region, bad):
        obj.release()
