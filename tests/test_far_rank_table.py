"""The far field's rank table (cover.rank_table, field.glsl far_rank_table): one filtered fetch per channel
gives the rank of the binary search it replaced (reference.level_rank: linear between each level's 33
quantiles, mixed between levels) within reference.rank_table_error's bound, on fresh random tables and
inputs (the seed is printed: ATMOS_TEST_SEED replays it)."""
import numpy as np

from atmos.gpu.uniforms import bind_buffers, bind_textures, write_uniforms
from atmos.plugins.clouds.far_field.cover import LEVELS, QUANTILES, RANK_COLUMNS, level_table, rank_table
from atmos.plugins.clouds.far_field.layer import rank_table_texture
from atmos.plugins.clouds.far_field.reference import level_rank, rank_table_error, table_rank

FIRST = 1.0         # field_first_level the GPU test sets: table row m is mip level m + 1


def random_table(rng):
    """(quantiles (LEVELS, QUANTILES), table, span) of a random texture setting (its octaves' seed, base
    frequency and size: 64 texels, whose coarse levels have the steepest ranks, up to 256)."""
    size, base = int(rng.choice([64, 128, 256])), int(rng.choice([2, 4, 8]))
    seed = int(rng.integers(2**32))
    print("table of", dict(size=size, base_frequency=base, seed=seed))
    quantiles = level_table(base, seed, size)[0]
    return (quantiles, *rank_table(quantiles))


def random_inputs(rng, quantiles, n):
    """(fbm (n, 4), level (n,)): uniform fbm from below the lowest quantile to above the highest, a
    quarter of them at a quantile (where the resampled table is off most); levels from below row 0 to
    above the last, a third of them whole (one row alone)."""
    lo, hi = quantiles[:, 0].min(), quantiles[:, -1].max()
    fbm = rng.uniform(lo - 0.05, hi + 0.05, (n, 4))
    knots = rng.random((n, 4)) < 0.25
    fbm[knots] = quantiles[rng.integers(0, LEVELS, knots.sum()), rng.integers(0, QUANTILES, knots.sum())]
    level = rng.uniform(-1.0, LEVELS + 1.0, n)
    whole = rng.random(n) < 1.0 / 3.0
    level[whole] = np.round(level[whole])
    return fbm, level


def test_the_table_lookup_model_keeps_the_exact_rank_within_its_bound(rng):
    """The float64 lookup (exact weights, float64 texels) is off the exact rank by the resampling bound at
    most, and by exactly that at a quantile of a whole level (the bound is the table's own); in float32
    texels with 8-bit weights (NVIDIA's filter) by at most the bound with the lookup's terms, small for
    RANK_COLUMNS."""
    quantiles, table, span = random_table(rng)
    assert table.shape == (LEVELS, RANK_COLUMNS)
    fbm, level = random_inputs(rng, quantiles, 50000)
    level = level[:, None]
    exact = level_rank(fbm, level, quantiles)
    resample, _ = rank_table_error(quantiles, table, span)
    model = table_rank(fbm, level, table, span, dtype=np.float64)
    assert np.abs(model - exact).max() <= resample + 1e-12
    rows = np.repeat(np.arange(LEVELS, dtype=np.float64), QUANTILES)           # every quantile in its own row
    at_knots = np.abs(table_rank(quantiles.ravel(), rows, table, span, dtype=np.float64)
                      - level_rank(quantiles.ravel(), rows, quantiles)).max()
    assert abs(at_knots - resample) < 1e-12, (at_knots, resample)
    resample, lookup = rank_table_error(quantiles, table, span, weight_bits=8)
    coarse = np.abs(table_rank(fbm, level, table, span, weight_bits=8) - exact).max()
    assert coarse <= resample + lookup, (coarse, resample, lookup)
    # 2.7e-3 at most over 60 settings (a 64-texel layer at base frequency 16, where the coarse levels'
    # quantiles crowd); the far field's tests hold its opacity to 0.01-0.02
    assert resample + lookup < 5e-3, (resample, lookup)
    print(f"resampling bound {resample:.2e}, with 8-bit weights {resample + lookup:.2e} (max off {coarse:.2e})")


def test_the_gpu_lookup_matches_the_model_and_the_exact_rank(gpu, ctx, rng, filter_bits):
    """field.glsl's fbm_rank on random fbm and mip levels (row m at mip m + FIRST, clamped at both ends)
    against table_rank as this GPU filters (filter_bits): within twice the lookup bound (each within it of
    the exactly weighted lookup); and against the exact rank within the whole bound."""
    quantiles, table, span = random_table(rng)
    fbm, level = random_inputs(rng, quantiles, 20000)
    n = len(level)
    texture = rank_table_texture(gpu, table)
    buffers = [ctx.buffer(np.ascontiguousarray(fbm, "f4").tobytes()), ctx.buffer(np.asarray(level + FIRST, "f4").tobytes()),
               ctx.buffer(reserve=16 * n)]
    program = gpu.program(compute_shader="test/rank_probe.comp")
    try:
        bind_textures(program, far_rank_table=texture)
        bind_buffers(program, Fbm=buffers[0], Lods=buffers[1], Ranks=buffers[2])
        write_uniforms(program, far_rank_span=tuple(span), field_first_level=FIRST, count=n)
        program.run((n + 63) // 64)
        ctx.memory_barrier()
        got = np.frombuffer(buffers[2].read(), np.float32).reshape(n, 4).astype(np.float64)
    finally:
        for obj in (texture, *buffers):
            obj.release()
    f32 = lambda a: np.asarray(a, np.float32).astype(np.float64)        # the GPU's inputs
    fbm, level = f32(fbm), (f32(level + FIRST) - FIRST)[:, None]
    resample, lookup = rank_table_error(quantiles, table, span, weight_bits=filter_bits)
    model = np.abs(got - table_rank(fbm, level, table, span, weight_bits=filter_bits)).max()
    exact = np.abs(got - level_rank(fbm, level, quantiles)).max()
    print(f"filter bits {filter_bits}: |GPU - model| {model:.2e} (<= {2 * lookup:.2e}), "
          f"|GPU - exact| {exact:.2e} (<= {resample + lookup:.2e})")
    assert model <= 2 * lookup, (model, lookup)
    assert exact <= resample + lookup, (exact, resample, lookup)
