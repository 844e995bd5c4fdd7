"""Resources that must not pile up: pooled textures of old sizes, timer queries, GL objects per frame."""
import moderngl
import pytest

from atmos.app import App
from atmos.defaults import DefaultPlugins
from atmos.slicing import FrameScheduler, SlicedJob, SliceTask, TripleSet, timer_query_measure
from atmos.slicing.job import TimerQueryMeasure
from atmos.gpu import MIN_GL_VERSION, create_headless
from atmos.gpu.queries import QueryPool, TimerQuery, query_pool
from atmos.graph import PassTimers, TextureDesc, TexturePool
from atmos.graph.timing import RING
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin

A = TextureDesc((8, 8))
B = TextureDesc((4, 4), 1, "f4")


def dead(texture) -> bool:
    return isinstance(texture.mglo, moderngl.InvalidObject)


def scene(gpu, **app_kw):
    """A cheap rendered scene: clear, sky gradient, ground, present (no overlay)."""
    app = App(gpu, **app_kw).add_plugins(DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin())
    app.startup()
    return app


@pytest.fixture
def count_queries(monkeypatch):
    """Counts every ``ctx.query(...)`` and :class:`TimerQuery` made in the test, whoever makes it."""
    made = []
    original, timer = moderngl.Context.query, TimerQuery.__init__

    def query(self, *args, **kwargs):
        made.append(1)
        return original(self, *args, **kwargs)

    def timer_query(self, gl):
        made.append(1)
        timer(self, gl)
    monkeypatch.setattr(moderngl.Context, "query", query)
    monkeypatch.setattr(TimerQuery, "__init__", timer_query)
    return made


# -- texture pool eviction ------------------------------------------------------------------------
def test_pool_evicts_a_desc_unused_for_keep_frames(gpu, ctx):
    pool = TexturePool(gpu, keep_frames=3)
    assert pool.keep_frames == 3 and pool.frame == 0 and pool.evictions == 0
    a = pool.acquire(A)
    pool.release(a)
    assert pool.end_frame() == 0        # frame 0: used
    assert pool.end_frame() == 0        # frame 1
    assert pool.end_frame() == 0        # frame 2: the last 3 frames (0, 1, 2) still include its use
    assert pool.textures == 1 and not dead(a)
    assert pool.end_frame() == 1        # frame 3: unused in frames 1, 2, 3
    assert pool.textures == 0 and pool.evictions == 1 and pool.frame == 4 and dead(a)
    assert A.key not in pool._free
    b = pool.acquire(A)                 # the desc comes back: a new texture
    assert b is not a and pool.allocations == 2
    pool.release(b)
    pool.release_all()


def test_pool_keeps_in_use_and_recently_used_textures(gpu, ctx):
    pool = TexturePool(gpu, keep_frames=2)

    def frame():                        # a frame that uses one A
        pool.release(pool.acquire(A))
        return pool.end_frame()
    held = pool.acquire(B)              # acquired once and kept for many frames
    every = pool.acquire(A)
    spare = pool.acquire(A)             # a second A, used only in the first frame
    pool.release(every)
    pool.release(spare)
    pool.end_frame()
    assert [frame() for _ in range(10)] == [0, 1] + [0] * 8     # the unused second A goes
    assert pool.in_use == 1 and not dead(held)
    assert pool.textures == 2 and pool.evictions == 1
    pool.release(held)                  # released now: counts as used in this frame
    assert frame() == 0 and frame() == 0 and not dead(held) and pool.textures == 2
    assert frame() == 1                 # unused in the last 2 frames
    assert dead(held) and pool.textures == 1 and pool.evictions == 2
    assert pool.allocations == 3
    pool.release_all()
    assert pool.textures == 0 and pool.in_use == 0


def test_pool_keep_frames_1_frees_whatever_this_frame_did_not_use(gpu, ctx):
    pool = TexturePool(gpu, keep_frames=1)
    a = pool.acquire(A)
    pool.release(a)
    assert pool.end_frame() == 0 and not dead(a)
    assert pool.end_frame() == 1 and dead(a)


def test_pool_bytes(gpu, ctx):
    pool = TexturePool(gpu)
    pool.acquire(A)                                     # 8 * 8 * 4 * 2
    pool.acquire(B)                                     # 4 * 4 * 1 * 4
    pool.acquire(TextureDesc((2, 2, 2), 2, "u1", filter="nearest"))  # 8 * 2
    assert pool.bytes == 512 + 64 + 16
    pool.release_all()
    assert pool.bytes == 0


@pytest.mark.parametrize("keep", [0, -1, 1.5, True, "3", None])
def test_pool_bad_keep_frames_is_a_clear_error(gpu, keep):
    with pytest.raises(ValueError, match=r"TexturePool keep_frames=.*: allowed is an int >= 1"):
        TexturePool(gpu, keep_frames=keep)


def test_pool_stays_bounded_over_30_resizes(fresh_gpu):
    fresh_gpu.resize((96, 54))
    app = scene(fresh_gpu)
    pool = app.graph.pool
    app.run_frames(3)
    steady, steady_bytes = pool.textures, pool.bytes
    assert steady > 0
    most = 0
    for k in range(30):
        fresh_gpu.resize((96 + 7 * k, 54 + 5 * k))
        app.run_frames(2)
        most = max(most, pool.textures)
        assert pool.in_use == 0
    # at most the sizes of the last keep_frames frames are held at once
    assert most <= steady * (pool.keep_frames + 1)
    fresh_gpu.resize((96, 54))
    app.run_frames(pool.keep_frames + 1)
    assert pool.textures == steady and pool.bytes == steady_bytes
    assert pool.evictions >= 30 * steady - steady
    assert app.graph._frame.cached_framebuffers <= 2 * steady + 4  # no framebuffers over evicted textures
    app.close()


# -- timer queries --------------------------------------------------------------------------------
def test_gpu_context_owns_its_query_pool(gpu, ctx):
    assert isinstance(gpu.queries, QueryPool) and query_pool(ctx) is gpu.queries
    other = create_headless((8, 8))
    assert other.queries is not gpu.queries
    other.release()
    gpu.make_current()


def test_query_pool_recycles_queries(count_queries):
    ctx = moderngl.create_standalone_context(require=MIN_GL_VERSION, backend="egl")
    pool = query_pool(ctx)
    q = pool.acquire()
    assert pool.made == 1 and pool.in_use == 1 and len(count_queries) == 1
    pool.release(q)
    assert pool.spare == 1 and pool.acquire() is q and pool.made == 1
    samples = pool.acquire(time=False, samples=True)     # another kind: another query
    assert samples is not q and pool.made == 2
    pool.release(q)
    with pytest.raises(ValueError, match="not acquired from this pool, or was already released"):
        pool.release(q)
    with pytest.raises(ValueError, match="at least one of time"):
        pool.acquire(time=False)
    ctx.release()


def test_pass_timers_of_two_graphs_share_the_context_queries(fresh_gpu, count_queries):
    gpu, ctx = fresh_gpu, fresh_gpu.ctx
    first = PassTimers(ctx)
    for _ in range(4):
        for name in ("a", "b"):
            with first.measure(name):
                pass
    made = len(count_queries)
    assert 0 < made <= 2 * RING and first.queries is gpu.queries
    first.release()
    second = PassTimers(ctx)
    for _ in range(4):
        for name in ("b", "c"):
            with second.measure(name):
                pass
    # the second graph takes the first's queries back from the pool: together never more than one
    # graph's worth (two passes of RING); how many a ring uses depends on when results come in
    assert made <= len(count_queries) <= 2 * RING
    second.release()


def test_timer_query_measure_holds_no_query_between_slices(fresh_gpu, count_queries):
    gpu, ctx = fresh_gpu, fresh_gpu.ctx
    in_use = gpu.queries.in_use
    measure = timer_query_measure(ctx)
    for _ in range(50):
        assert measure(lambda: None) >= 0.0
        assert gpu.queries.in_use == in_use
    assert len(count_queries) == gpu.queries.made == 1


def tiny_job(gpu):
    """A job of 4 cheap slices a step (each writes a texel row of C)."""
    triple = TripleSet(gpu, {"v": TextureDesc((4, 4), 1, "f4", filter="nearest")})

    def run(index, job_ctx):
        job_ctx.target["v"].write(bytes(16), viewport=(0, index, 4, 1))
    return SlicedJob("tiny", [SliceTask("rows", 4, run)], triple)


def gl_objects(app, gpu, made):
    graph = app.graph
    return {"pool textures": graph.pool.textures, "pool allocations": graph.pool.allocations,
            "queries made": len(made), "query pool": gpu.queries.made,
            "framebuffers": graph._frame.cached_framebuffers, "tracked": len(gpu._tracked),
            "programs": len(gpu._programs)}


def test_2000_frames_with_a_time_budget_make_no_queries_or_gl_objects(fresh_gpu, count_queries, monkeypatch):
    # timer queries even on llvmpipe (whose results mean nothing, but they are made and read the same)
    monkeypatch.setattr("atmos.slicing.job.is_software", lambda ctx: False)
    app = scene(fresh_gpu)
    app.frames = FrameScheduler(time_budget_ms=1000.0)
    job = app.frames.add(tiny_job(fresh_gpu))
    app.run_frames(10)
    before = gl_objects(app, fresh_gpu, count_queries)
    assert before["queries made"] > 0
    app.run_frames(2000)
    after = gl_objects(app, fresh_gpu, count_queries)
    ring = TimerQueryMeasure.DEPTH             # the measure's ring: queries are made as results lag, never more
    assert before["queries made"] <= after["queries made"] == after["query pool"] <= ring
    for name in ("queries made", "query pool"):
        del before[name], after[name]
    assert after == before
    assert job.step >= 2000 and app.frames.slices_last_frame == 4   # one step a frame, budget permitting
    assert job.stats.slices_measured > 0.9 * job.stats.slices_total    # the costs came in, late
    assert fresh_gpu.queries.in_use > 0
    app.close()
    assert fresh_gpu.queries.in_use == 0                                # the scheduler gave its ring back


def test_50_apps_on_one_context_reuse_the_same_queries(fresh_gpu, count_queries):
    made = []
    for _ in range(50):
        app = scene(fresh_gpu)
        app.graph.timings_enabled = True
        app.run_frames(3)
        kept = len(app.graph.compile().kept)
        app.close()
        made.append(len(count_queries))
    # a pass takes a second query of its ring only while the first one's result is still out
    assert 0 < made[0] and made[-1] <= RING * kept, made
    assert fresh_gpu.queries.made == made[-1] and fresh_gpu.queries.in_use == 0


def test_a_cleared_buffer_is_zeroed_by_a_queued_write_never_a_mapping(gpu, monkeypatch):
    """A pooled buffer with ``clear`` comes back zero-filled each time, through glBufferSubData: moderngl's
    Buffer.clear maps the buffer, which waits for the GPU to finish with it."""
    import numpy as np

    from atmos.graph import BufferDesc

    def mapping(self, *args, **kwargs):
        raise AssertionError("Buffer.clear maps the buffer (a wait for the GPU)")

    pool = TexturePool(gpu)
    desc = BufferDesc(64, clear=True)
    buffer = pool.acquire(desc)
    buffer.write(np.arange(16, dtype=np.uint32).tobytes())
    pool.release(buffer)
    monkeypatch.setattr(moderngl.Buffer, "clear", mapping)
    again = pool.acquire(desc)
    assert again is buffer and not any(again.read())
    pool.release(again)
    pool.release_all()
