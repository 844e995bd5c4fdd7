"""Per-pass timer queries: off unless something shows or records them, read only once the GPU has
their result (never waiting), in a bounded ring per pass, given back when passes go."""
from atmos.app import App
from atmos.defaults import DefaultPlugins
from atmos.gpu import queries
from atmos.gpu.gl_meter import GLMeter
from atmos.gpu.queries import ModernglTimerQuery, TimerQuery, query_pool
from atmos.graph import PassTimers
from atmos.graph.timing import RING
from atmos.overlay import OverlayPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.graph import TextureDesc
from atmos.slicing import FrameScheduler, SlicedJob, SliceTask, TripleSet

QUERY_CALLS = ("TimerQuery.begin", "TimerQuery.poll", "TimerQuery.result", "Query.elapsed")


def scene(gpu, overlay=False):
    app = App(gpu).add_plugins(DefaultPlugins(overlay=overlay), SkyGradientPlugin(), GroundPlugin())
    app.startup()
    return app


def kept(app) -> int:
    return len(app.graph.compile().kept)


def test_frames_make_no_query_while_nothing_wants_timings(fresh_gpu):
    app = scene(fresh_gpu)
    assert app.graph.timings_enabled is False
    with GLMeter() as meter:
        app.run_frames(5)
    assert [meter.calls[c] for c in QUERY_CALLS] == [0, 0, 0, 0] and meter.readbacks == []
    assert fresh_gpu.queries.made == 0 and app.graph.timings == {}
    app.close()


def test_timings_on_come_in_without_a_waiting_read(fresh_gpu):
    app = scene(fresh_gpu)
    app.graph.timings_enabled = True
    for _ in range(20):
        app.run_frames(1)
        if len(app.graph.timings) == kept(app):
            break
    assert set(app.graph.timings) == set(app.graph.compile().kept)
    with GLMeter() as meter:
        app.run_frames(30)
    assert meter.readbacks == [], [r.call + " " + r.where for r in meter.readbacks]
    assert meter.calls["TimerQuery.result"] == meter.calls["Query.elapsed"] == 0
    assert meter.calls["TimerQuery.begin"] > 0 and meter.calls["TimerQuery.poll"] > 0
    for gpu_ms, cpu_ms in app.graph.timings.values():
        assert gpu_ms >= 0.0 and cpu_ms >= 0.0
    app.close()


def test_the_rings_stay_bounded_and_go_back_when_timing_stops(fresh_gpu):
    app = scene(fresh_gpu)
    app.graph.timings_enabled = True
    for _ in range(300):
        app.run_frames(1)
        assert app.graph._timers.held <= RING * kept(app)
    pool = fresh_gpu.queries
    assert 0 < pool.made <= RING * kept(app) and pool.in_use == app.graph._timers.held
    results = dict(app.graph.timings)
    app.graph.timings_enabled = False
    with GLMeter() as meter:
        app.run_frames(3)
    assert meter.calls["TimerQuery.begin"] == meter.calls["TimerQuery.poll"] == 0
    assert pool.in_use == 0 and app.graph.timings == results     # the queries went back, the numbers stay
    app.close()


def test_removed_and_culled_passes_give_their_queries_back(fresh_gpu):
    app = scene(fresh_gpu, overlay=True)                        # the overlay shows: it wants timings
    graph, pool = app.graph, fresh_gpu.queries
    assert graph.timings_enabled
    app.run_frames(4)
    assert "overlay" in graph._timers._rings and pool.in_use == graph._timers.held > 0
    overlay = next(p for p in app.plugins if isinstance(p, OverlayPlugin))
    graph.timings_enabled = True                                # kept on by hand once the overlay hides
    overlay.configure(visible=False)                            # the overlay pass is culled
    app.run_frames(2)
    assert "overlay" not in graph._timers._rings and "overlay" not in graph.timings
    assert pool.in_use == graph._timers.held
    graph.remove_pass("ground")
    assert "ground" not in graph._timers._rings and pool.in_use == graph._timers.held
    app.close()
    assert pool.in_use == 0


def test_the_overlay_wants_timings_only_while_it_shows(fresh_gpu):
    app = scene(fresh_gpu, overlay=False)
    overlay = next(p for p in app.plugins if isinstance(p, OverlayPlugin))
    app.run_frames(2)
    assert not app.graph.timings_enabled and fresh_gpu.queries.made == 0
    overlay.configure(visible=True)
    app.run_frames(3)
    assert app.graph.timings_enabled and fresh_gpu.queries.in_use > 0
    app.graph.want_timings("benchmark")                         # a second consumer
    overlay.configure(visible=False)
    app.run_frames(1)
    assert app.graph.timings_enabled
    app.graph.want_timings("benchmark", False)
    app.run_frames(1)
    assert not app.graph.timings_enabled and fresh_gpu.queries.in_use == 0
    app.close()


class Slow:
    """A stand-in query whose result (its frame's number) comes in ``lag`` frames after it ended
    (never, with None)."""

    def __init__(self, pool):
        self.pool = pool

    def begin(self):
        pass

    def end(self):
        self.ended = self.pool.frame

    def flush(self):
        pass

    def poll(self):
        lag = self.pool.lag
        return float(self.ended) if lag is not None and self.pool.frame >= self.ended + lag else None


class FakePool:
    def __init__(self, lag):
        self.lag, self.out, self.frame = lag, set(), 0

    def timer(self):
        query = Slow(self)
        self.out.add(query)
        return query

    def release(self, query):
        self.out.remove(query)


def test_a_ring_whose_results_never_come_skips_frames_and_never_grows(ctx):
    pool = FakePool(lag=None)
    timers = PassTimers(ctx, pool)
    for pool.frame in range(50):
        with timers.measure("stuck"):
            pass
    assert len(pool.out) == RING and timers.held == RING
    assert timers.dropped == 50 - RING and timers.results == {}
    timers.release()
    assert not pool.out


def test_results_are_the_latest_measurement_that_came_in(ctx):
    pool = FakePool(lag=3)
    timers = PassTimers(ctx, pool)
    got = []
    for pool.frame in range(12):
        with timers.measure("p"):
            pass
        got.append(timers.results.get("p", (None,))[0])
    assert got == [None] * 3 + list(range(9)), got              # frame k's result is read on frame k + 3
    assert timers.dropped == 0 and len(pool.out) == 3           # three in flight at a time
    pool.lag = 6                                                # the GPU falls behind: frames go unmeasured
    for pool.frame in range(12, 24):
        with timers.measure("p"):
            pass
        assert len(pool.out) == RING
    assert timers.dropped > 0 and timers.results["p"][0] <= 24 - 6
    timers.release()


def test_timer_queries_without_gl_functions_fall_back_to_moderngl(fresh_gpu, monkeypatch):
    monkeypatch.setattr(queries, "gl_functions", lambda: None)
    timers = PassTimers(fresh_gpu.ctx)
    fresh_gpu.target.use()
    for _ in range(5):
        with timers.measure("p"):
            fresh_gpu.ctx.clear(0.5, 0.5, 0.5)
    assert isinstance(timers._rings["p"].queries[0], ModernglTimerQuery)
    assert "p" in timers.results and timers.held <= RING
    timers.release()


def test_a_timer_query_of_our_own_is_deleted_with_its_context(fresh_gpu):
    pool = query_pool(fresh_gpu.ctx)
    query = pool.timer()
    assert isinstance(query, TimerQuery) and query.glo > 0
    fresh_gpu.target.use()
    query.begin()
    fresh_gpu.ctx.clear(0.2, 0.2, 0.2)
    query.end()
    assert query.result() >= 0.0
    pool.release(query)
    fresh_gpu.make_current()
    pool.clear()
    assert query.glo == 0


def tiny_job(gpu):
    triple = TripleSet(gpu, {"v": TextureDesc((4, 4), 1, "f4", filter="nearest")})

    def run(index, job_ctx):
        job_ctx.target["v"].write(bytes(16), viewport=(0, index, 4, 1))
    return SlicedJob("tiny", [SliceTask("rows", 4, run)], triple)


def test_a_time_budget_reads_slice_timer_queries_without_waiting(fresh_gpu, monkeypatch):
    monkeypatch.setattr("atmos.slicing.job.is_software", lambda ctx: False)   # timer queries on llvmpipe
    app = scene(fresh_gpu)
    app.frames = FrameScheduler(time_budget_ms=1000.0)
    job = app.frames.add(tiny_job(fresh_gpu))
    app.run_frames(5)
    with GLMeter() as meter:
        app.run_frames(40)
    assert meter.readbacks == [] and meter.calls["Context.finish"] == 0
    assert meter.calls["TimerQuery.begin"] > 0 and meter.calls["TimerQuery.result"] == 0
    assert job.stats.slices_measured > 0 and job.expected_slice_ms() is not None
    assert app.frames.slices_last_frame == 4                  # the budget runs on the costs that came in
    app.close()
    assert fresh_gpu.queries.in_use == 0


def test_a_fence_says_when_the_gpu_is_done_without_waiting(ctx, monkeypatch):
    from atmos.gpu import queries
    buffer = ctx.buffer(reserve=4 << 20)
    buffer.clear()
    fence = queries.Fence()
    assert fence._sync is not None, "the sync functions resolve on an EGL context"
    ctx.finish()
    assert fence.done() and fence._sync is None and fence.done()     # deleted once done, still done
    fence.delete()
    buffer.release()
    monkeypatch.setattr(queries, "_sync_functions", lambda: None)     # no sync functions: done the second time
    fallback = queries.Fence()
    assert not fallback.done() and fallback.done()
