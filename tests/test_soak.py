"""A short soak (benchmarks/bench_soak.py): the cloud scene with weather churn, live setting changes,
time-of-day jumps and resizes runs without an error and without growing its live GL objects; Apps
made and closed one after another leave nothing behind. Counting, never timing."""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import bench_soak  # noqa: E402

from atmos.gpu.census import GLCensus  # noqa: E402


@pytest.fixture(scope="module")
def census():
    with GLCensus() as c:
        yield c


def test_a_short_soak_has_no_errors_and_flat_gl_objects(census):
    result = bench_soak.soak(600, seed=1, census=census)        # 5 cycles of the 6 window sizes
    assert result["errors"] == []
    assert result["refused"] == 3 and result["warnings"] == result["bad_ellipsoids"] == 1
    first, last = bench_soak.quarter_max(result["objects"])
    assert last <= first, f"live GL objects grew from {first} to {last} over the soak"
    assert result["objects"][-1] <= first


def test_apps_made_and_closed_on_one_context_leave_no_gl_objects(census):
    result = bench_soak.apps_churn(6, shared=True, census=census)
    assert result["errors"] == []
    assert len(set(result["objects"])) == 1, f"live GL objects after each App: {result['objects']}"


def test_apps_on_contexts_of_their_own_leave_no_context_alive(census):
    result = bench_soak.apps_churn(4, shared=False, census=census)
    assert result["errors"] == [] and result["objects"] == [0, 0, 0, 0]


def test_the_census_counts_what_is_made_and_not_released(fresh_gpu, census):
    ctx = fresh_gpu.ctx
    before = census.live(ctx)
    texture, buffer = ctx.texture((4, 4), 4), ctx.buffer(reserve=16)
    assert census.live(ctx) - before == {"Texture": 1, "Buffer": 1}
    texture.release()
    buffer.release()
    assert census.live(ctx) == before
