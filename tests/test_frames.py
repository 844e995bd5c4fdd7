"""atmos.slicing: three texture sets, sliced jobs and the frame scheduler."""
import moderngl
import numpy as np
import pytest

from atmos.slicing import FrameScheduler, SlicedJob, SliceTask, TextureSet, TripleSet, make_texture
from atmos.graph import TextureDesc as Desc
from atmos.gpu.uniforms import bind_images


SIZE = (8, 4, 6)          # x, y, z: one z-layer per slice
FEEDBACK = 0.5


def fill_job(gpu, name="fill", size=SIZE, layers_per_slice=1, log=None):
    """A deterministic job: each slice writes z-layers of C from (x, y, z, step) and B (see frames_fill.comp)."""
    triple = TripleSet(gpu, {"vol": Desc(size, 4, "f4", filter="nearest")})
    program = gpu.program(compute_shader="test/frames_fill.comp")
    slices = -(-size[2] // layers_per_slice)

    def begin(step):
        job.state["step_value"] = float(step)
        if log is not None:
            log.append(("begin", step))

    def run(index, job_ctx):
        if log is not None:
            log.append(("slice", job_ctx.step, index))
        bind_images(program, dst=job_ctx.target["vol"], src=job_ctx.previous["vol"])
        program["z0"] = index * layers_per_slice
        program["step_value"] = job_ctx.state["step_value"]
        program["feedback"] = FEEDBACK
        layers = min(layers_per_slice, size[2] - index * layers_per_slice)
        program.run(size[0] // 4, size[1] // 4, layers)

    job = SlicedJob(name, [SliceTask("fill", slices, run)], triple, begin=begin)
    return job


def read(texture_set, name="vol", size=SIZE):
    """Texture contents as float32 [x, y, z, c]."""
    data = np.frombuffer(texture_set[name].read(), np.float32).reshape(size[2], size[1], size[0], 4)
    return data.transpose(2, 1, 0, 3).copy()


def displayed(job):
    a, b, t = job.view()
    return (1.0 - t) * read(a).astype(np.float64) + t * read(b).astype(np.float64)


# -- texture sets ----------------------------------------------------------------------------

def test_make_texture_kinds(gpu, ctx):
    t2 = make_texture(gpu, Desc((4, 3), 2, "f2"))
    t3 = make_texture(gpu, Desc((4, 3, 2), 4, "f4", filter="nearest"))
    depth = make_texture(gpu, Desc((4, 3), 1, "f4", depth=True))
    assert isinstance(t2, moderngl.Texture) and t2.size == (4, 3) and t2.components == 2 and t2.dtype == "f2"
    assert isinstance(t3, moderngl.Texture3D) and t3.size == (4, 3, 2) and t3.filter == (moderngl.NEAREST,) * 2
    assert t2.filter == (moderngl.LINEAR, moderngl.LINEAR)
    assert isinstance(depth, moderngl.Texture) and depth.depth
    assert not np.frombuffer(t3.read(), np.float32).any()   # cleared, never undefined
    for texture in (t2, t3, depth):
        texture.release()


def test_make_texture_needs_a_texture_desc(gpu, ctx):
    with pytest.raises(ValueError, match="allowed is an atmos.graph.TextureDesc"):
        make_texture(gpu, {"size": (4, 4)})


def test_triple_rotation_order(gpu, ctx):
    triple = TripleSet(gpu, {"density": Desc((4, 4, 4)), "light": Desc((4, 4))})
    s0, s1, s2 = triple.a, triple.b, triple.c
    assert len({id(s) for s in (s0, s1, s2)}) == 3
    assert len({id(s[n]) for s in (s0, s1, s2) for n in ("density", "light")}) == 6
    assert isinstance(s0, TextureSet) and s0["density"].size == (4, 4, 4) and "light" in s0
    expected = [(s0, s1, s2), (s1, s2, s0), (s2, s0, s1), (s0, s1, s2)]
    versions = {id(s): 0 for s in (s0, s1, s2)}
    for generation, (a, b, c) in enumerate(expected):
        assert triple.generation == generation
        assert (triple.a, triple.b, triple.c) == (a, b, c)
        assert all(x is y for x, y in zip(triple.sets, (a, b, c)))
        assert all(s.version == versions[id(s)] for s in (a, b, c)), "only a set made anew (the new B) counts"
        triple.rotate()
        versions[id(c)] += 1
    with pytest.raises(KeyError, match="no texture 'fog'.*density, light"):
        triple.a["fog"]
    triple.release()


def test_triple_needs_descs(gpu, ctx):
    with pytest.raises(ValueError, match="at least one texture description"):
        TripleSet(gpu, {})


# -- sliced jobs -----------------------------------------------------------------------------

def test_progress_over_a_step(gpu, ctx):
    log = []
    job = fill_job(gpu, log=log)
    n = SIZE[2]
    assert job.slices_in_step == n and job.progress == 0.0 and job.step == 0
    seen = []
    for _ in range(n):
        seen.append(job.progress)
        assert job.run_slices(1) == 1
    assert seen == pytest.approx([i / n for i in range(n)])
    assert job.step == 1 and job.progress == 0.0 and job.triple.generation == 1
    assert log == [("begin", 0)] + [("slice", 0, i) for i in range(n)]
    job.run_slices(2)
    assert job.progress == pytest.approx(2 / n) and log[-3:] == [("begin", 1), ("slice", 1, 0), ("slice", 1, 1)]
    job.release()


def test_tasks_run_in_order_with_callable_counts(gpu, ctx):
    triple = TripleSet(gpu, {"x": Desc((2, 2))})
    calls, counts = [], {"b": 3}

    def task(name):
        return lambda i, job_ctx: calls.append((job_ctx.step, name, i, job_ctx.slices,
                                                job_ctx.target is triple.c, job_ctx.previous is triple.b))

    job = SlicedJob("chain", [SliceTask("a", 2, task("a")), SliceTask("empty", 0, task("empty")),
                              SliceTask("b", lambda: counts["b"], task("b"))], triple)
    job.run_step()
    assert calls == [(0, "a", 0, 2, True, True), (0, "a", 1, 2, True, True),
                     (0, "b", 0, 3, True, True), (0, "b", 1, 3, True, True), (0, "b", 2, 3, True, True)]
    counts["b"] = 1                       # asked again at the start of each step
    job.run_slices(1)
    assert job.slices_in_step == 3 and job.progress == pytest.approx(1 / 3)
    counts["b"] = 5                       # fixed once the step began
    job.run_step()
    assert job.step == 2 and [c[1] for c in calls[5:]] == ["a", "a", "b"]
    assert job.stats.slices_total == 8 and job.stats.mean_slice_ms >= 0.0
    assert set(job.stats.task_ms) == {"a", "b"}
    triple.release()


def test_prime_fills_a_and_b(gpu, ctx):
    job = fill_job(gpu)
    assert not job.ready
    job.prime()
    assert job.step == 2 and job.ready and job.progress == 0.0
    a, b, t = job.view()
    x = np.arange(SIZE[0], dtype=np.float32)[:, None, None]
    assert t == 0.0
    np.testing.assert_allclose(read(a)[..., 0], np.broadcast_to(0.0 + 0.01 * x, SIZE), rtol=1e-6)
    np.testing.assert_allclose(read(b)[..., 0], np.broadcast_to(1.0 + 0.01 * x, SIZE), rtol=1e-6)
    job.prime()                           # already primed: nothing more
    assert job.step == 2
    job.release()


def test_readers_never_see_c(gpu, ctx):
    job = fill_job(gpu)
    job.prime()
    for _ in range(2):                    # two full steps, checked slice by slice
        a, b, _ = job.view()
        a_data, b_data = read(a), read(b)
        c = job.triple.c
        for i in range(SIZE[2]):
            view_a, view_b, _ = job.view()
            assert view_a is a and view_b is b
            assert view_a is not job.triple.c and view_b is not job.triple.c
            np.testing.assert_array_equal(read(view_a), a_data)
            np.testing.assert_array_equal(read(view_b), b_data)
            job.run_slices(1)
            if i < SIZE[2] - 1:           # C is being written layer by layer, and only C
                assert job.triple.c is c
                expected = job.step + 0.01 * np.arange(SIZE[0], dtype=np.float32)[:, None]
                np.testing.assert_allclose(read(c)[:, :, i, 0], np.broadcast_to(expected, SIZE[:2]), rtol=1e-6)
        new_a, new_b, t = job.view()      # rotated only after the last slice of C
        assert new_a is b and new_b is c and t == 0.0 and job.triple.c is a
        np.testing.assert_array_equal(read(new_a), b_data)
    job.release()


def test_continuity_across_rotation(gpu, ctx):
    job = fill_job(gpu)
    job.prime()
    n = SIZE[2]
    frames = []
    for frame in range(3 * n):
        before = job.triple.generation
        if job.slices_done == n - 1:      # the next slice completes C: the shown pair at t = 1 ...
            a, b, _ = job.view()
            at_one = read(b).astype(np.float64)
            at_one_mix = 0.0 * read(a) + 1.0 * at_one
        frames.append(displayed(job)[..., 0])
        job.run_slices(1)
        if job.triple.generation != before:   # ... equals the new pair at t = 0
            a, b, t = job.view()
            assert t == 0.0
            np.testing.assert_array_equal((1.0 - t) * read(a) + t * read(b), at_one_mix)
    # the shown value (x channel = step + 0.01 x) rises by exactly 1/n per frame, across rotations too
    steps = np.diff(np.stack(frames), axis=0)
    np.testing.assert_allclose(steps, 1.0 / n, rtol=1e-9, atol=1e-6)
    assert job.step == 2 + 3
    job.release()


@pytest.mark.parametrize("slices_per_frame, layers_per_slice", [(1, 1), (4, 1), (2, 4)])
def test_naive_and_sliced_agree(gpu, ctx, slices_per_frame, layers_per_slice):
    steps = 4
    naive_job = fill_job(gpu, "naive", layers_per_slice=layers_per_slice)
    sliced_job = fill_job(gpu, "sliced", layers_per_slice=layers_per_slice)
    naive = FrameScheduler("naive")
    naive.add(naive_job)
    for _ in range(steps):
        naive.tick()
        assert naive.stats["naive"].slices_last_frame == naive_job.slices_in_step
    sliced = FrameScheduler("sliced", slices_per_frame=slices_per_frame)
    sliced.add(sliced_job)
    ticks = 0
    while sliced_job.step < steps:
        sliced.tick()
        ticks += 1
    # a frame that ends a step goes on into the next one: the slices run are spread evenly over frames
    assert ticks == -(-steps * sliced_job.slices_in_step // slices_per_frame)
    assert naive_job.step == sliced_job.step == steps
    for name in "abc":
        np.testing.assert_array_equal(read(getattr(naive_job.triple, name)), read(getattr(sliced_job.triple, name)))
    # the feedback channel really depends on the previous result
    b = read(sliced_job.triple.b)
    assert not np.allclose(b[..., 2], b[..., 1])
    naive_job.release()
    sliced_job.release()


# -- scheduler -------------------------------------------------------------------------------

@pytest.mark.parametrize("k", [1, 2, 5])
def test_slices_per_frame(gpu, ctx, k):
    job = fill_job(gpu, size=(8, 4, 20))
    scheduler = FrameScheduler(slices_per_frame=k)
    scheduler.add(job)
    for frame in range(3):
        scheduler.tick()
        assert scheduler.stats["fill"].slices_last_frame == k
        assert scheduler.slices_last_frame == k
        assert job.slices_done == (frame + 1) * k
    stats = scheduler.stats["fill"]
    assert stats.steps == 0 and stats.mean_slice_ms > 0.0 and stats.progress == pytest.approx(3 * k / 20)
    job.release()


def test_round_robin_over_jobs(gpu, ctx):
    jobs = [fill_job(gpu, f"job{i}", size=(8, 4, 12)) for i in range(3)]
    scheduler = FrameScheduler(slices_per_frame=2)
    for job in jobs:
        scheduler.add(job)
    for _ in range(3):
        scheduler.tick()
        assert scheduler.slices_last_frame == 2
    assert [job.slices_done for job in jobs] == [2, 2, 2]
    scheduler.remove(jobs[1])
    assert jobs[1] not in scheduler and list(scheduler.stats) == ["job0", "job2"]
    for job in jobs:
        job.release()


def test_time_budget_runs_at_least_one_slice(gpu, ctx):
    job = fill_job(gpu)
    scheduler = FrameScheduler(time_budget_ms=1e-9)
    scheduler.add(job)
    for frame in range(SIZE[2] + 2):
        scheduler.tick()
        assert scheduler.stats["fill"].slices_last_frame == 1
    assert job.step == 1 and job.slices_done == 2
    job.release()


def test_time_budget_with_measure_hook(gpu, ctx):
    job = fill_job(gpu, size=(8, 4, 12))
    timed = []

    def measure(run):                     # a pluggable timer: here every slice "costs" 1 ms
        run()
        timed.append(1)
        return 1.0

    scheduler = FrameScheduler(time_budget_ms=3.5, measure=measure)
    scheduler.add(job)
    scheduler.tick()
    assert scheduler.stats["fill"].slices_last_frame == 3 and scheduler.ms_last_frame == 3.0
    assert scheduler.stats["fill"].mean_slice_ms == 1.0 and len(timed) == 3
    scheduler.tick()
    scheduler.tick()
    assert job.slices_done == 9
    scheduler.tick()                      # the last 3 slices: a rotation
    assert job.step == 1 and job.slices_done == 0
    big = FrameScheduler(time_budget_ms=1e6, measure=measure)
    big.add(job)
    big.tick()                            # a whole step, then on into the next but for its rotating slice
    assert big.stats["fill"].slices_last_frame == 23 and job.step == 2 and job.slices_done == 11
    job.release()


def test_time_budget_syncs_and_measures(gpu, ctx):
    job = fill_job(gpu)
    scheduler = FrameScheduler(time_budget_ms=1000.0)
    assert scheduler.sync
    scheduler.add(job)
    scheduler.tick()
    assert scheduler.stats["fill"].slices_last_frame == 2 * SIZE[2] - 1 and job.step == 1   # never two rotations
    assert 0.0 < scheduler.stats["fill"].mean_slice_ms < 1000.0
    job.release()


@pytest.mark.parametrize("budget", [None, 3.5])
def test_interpolation_advances_evenly_across_rotations(gpu, ctx, budget):
    """The shown time step + t rises by the same amount every frame, the frames that end a step too
    (the scheduler used to stop a job after its rotation: one frame in a few barely moved)."""
    job = fill_job(gpu, size=(8, 4, 10))
    scheduler = FrameScheduler(slices_per_frame=3, time_budget_ms=budget, measure=lambda run: (run(), 1.0)[1])
    scheduler.add(job)
    shown = []
    for _ in range(40):
        scheduler.tick()
        shown.append(job.step + job.progress)
    increments = np.diff(shown)
    assert job.step == 12
    np.testing.assert_allclose(increments, 0.3, atol=1e-9)


def test_no_jobs_ticks_fine(ctx):
    for scheduler in (FrameScheduler(), FrameScheduler("naive"), FrameScheduler(time_budget_ms=2.0)):
        scheduler.tick()
        scheduler.tick()
        assert scheduler.stats == {} and scheduler.slices_last_frame == 0 and scheduler.frame == 2


@pytest.mark.parametrize("kwargs, message", [
    ({"mode": "eager"}, r"FrameScheduler.mode must be one of 'sliced', 'naive', got 'eager'"),
    ({"slices_per_frame": 0}, r"FrameScheduler.slices_per_frame must be a whole number 1..1000000, got 0"),
    ({"slices_per_frame": 1.5}, r"FrameScheduler.slices_per_frame must be a whole number 1..1000000, got 1.5"),
    ({"time_budget_ms": 0}, r"FrameScheduler.time_budget_ms must be a finite number > 0.0 or None, got 0"),
    ({"time_budget_ms": -2.0}, r"FrameScheduler.time_budget_ms must be .*, got -2.0"),
    ({"time_budget_ms": float("nan")}, r"FrameScheduler.time_budget_ms must be .*, got nan"),
    ({"measure": 3}, r"FrameScheduler.measure must be None or a callable"),
    ({"sync": "yes"}, r"FrameScheduler.sync must be True or False"),
])
def test_bad_scheduler_arguments(kwargs, message):
    with pytest.raises(ValueError, match=message):
        FrameScheduler(**kwargs)


@pytest.mark.parametrize("name, value", [("slices_per_frame", 0), ("slices_per_frame", -1), ("time_budget_ms", 0.0),
                                         ("time_budget_ms", float("inf")), ("mode", "eager"), ("measure", 3)])
def test_a_bad_scheduler_setting_assigned_while_running_is_refused_and_changes_nothing(name, value):
    """``app.frames.slices_per_frame = 0`` used to stop every sliced job without a word."""
    scheduler = FrameScheduler(slices_per_frame=2, time_budget_ms=None)
    before = getattr(scheduler, name)
    with pytest.raises(ValueError, match=f"FrameScheduler.{name} must be"):
        setattr(scheduler, name, value)
    assert getattr(scheduler, name) == before


def test_bad_job_arguments(gpu, ctx):
    triple = TripleSet(gpu, {"x": Desc((2, 2))})
    noop = lambda i, job_ctx: None  # noqa: E731
    with pytest.raises(ValueError, match=r"task 'a': slices must be an int >= 0.*got -1"):
        SliceTask("a", -1, noop)
    with pytest.raises(ValueError, match=r"task 'a': run must be callable"):
        SliceTask("a", 1, None)
    with pytest.raises(ValueError, match=r"job 'j' needs at least one SliceTask"):
        SlicedJob("j", [], triple)
    empty = SlicedJob("j", [SliceTask("a", lambda: 0, noop)], triple)
    with pytest.raises(ValueError, match=r"job 'j': step 0 has no slices"):
        empty.run_slices(1)
    bad_count = SlicedJob("j", [SliceTask("a", lambda: "3", noop)], triple)
    with pytest.raises(ValueError, match=r"task 'a': slices must be an int"):
        bad_count.run_step()
    job = SlicedJob("j", [SliceTask("a", 2, noop)], triple)
    with pytest.raises(ValueError, match=r"n must be an int >= 0; got -1"):
        job.run_slices(-1)
    assert job.run_slices(0) == 0
    scheduler = FrameScheduler()
    scheduler.add(job)
    with pytest.raises(ValueError, match="already in this FrameScheduler"):
        scheduler.add(job)
    with pytest.raises(ValueError, match=r"a job named 'j' is already.*must be unique"):
        scheduler.add(SlicedJob("j", [SliceTask("a", 2, noop)], triple))
    with pytest.raises(ValueError, match=r"job 'other' is not in this FrameScheduler; present: j"):
        scheduler.remove(SlicedJob("other", [SliceTask("a", 2, noop)], triple))
    triple.release()


def test_failed_slice_is_retried(gpu, ctx):
    triple = TripleSet(gpu, {"x": Desc((2, 2))})
    calls = []

    def run(i, job_ctx):
        calls.append(i)
        if len(calls) == 2:
            raise RuntimeError("boom")

    job = SlicedJob("j", [SliceTask("a", 3, run)], triple)
    job.run_slices(1)
    with pytest.raises(RuntimeError, match="boom"):
        job.run_slices(1)
    assert job.slices_done == 1 and triple.generation == 0
    job.run_step()
    assert calls == [0, 1, 1, 2] and job.step == 1 and triple.generation == 1
    triple.release()


def test_gpu_measure_times_a_slice(ctx):
    from atmos.slicing import gpu_measure, timer_query_measure
    ran = []
    for measure in (gpu_measure(ctx), timer_query_measure(ctx)):
        ms = measure(lambda: ran.append(1))
        assert ms >= 0.0 and ms == ms
    assert ran == [1, 1]
