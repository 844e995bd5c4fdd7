"""A simulation chain split into slices, computed a few slices per frame into texture set C.

A :class:`SlicedJob` is a list of :class:`SliceTask` (for clouds: region volume → automaton step
→ smoothing → density maps → shading). One *step* runs every slice of every task, in order,
writing into ``triple.c`` and reading the previous result ``triple.b``. When the last slice of a
step finishes the triple rotates, so readers, who only ever get ``(A, B, t)`` from :meth:`view`,
never see a half-written set.
"""
from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, field
from typing import Callable

from atmos.slicing.texture_sets import TextureSet, TripleSet
from atmos.gpu.host_memory import is_software
from atmos.gpu.queries import query_pool

Measure = Callable[[Callable[[], None]], float]
"""Runs the given callable (one slice) and returns how long it took in milliseconds."""


def perf_measure(run: Callable[[], None]) -> float:
    """Wall time of ``run()`` in ms with ``time.perf_counter`` (submission cost unless the GPU is synced)."""
    start = time.perf_counter()
    run()
    return (time.perf_counter() - start) * 1000.0


def synced_measure(ctx) -> Measure:
    """A measure that waits for the GPU (``ctx.finish()``) before and after the slice, so it times the GPU work.

    GPU timer queries are meaningless on llvmpipe; plug a timer-query measure in where they are not.
    """
    def measure(run: Callable[[], None]) -> float:
        ctx.finish()
        start = time.perf_counter()
        run()
        ctx.finish()
        return (time.perf_counter() - start) * 1000.0
    return measure


class TimerQueryMeasure:
    """A measure from an OpenGL timer query around each slice: the GPU's own time for its commands.

    Called as a :data:`Measure` it waits for the result. A :class:`SlicedJob` calls :meth:`submit`
    instead (when ``late``): the slice runs inside a query of a ring of ``depth``, and ``done(ms)``
    is called once its result is in, from a later :meth:`submit` or :meth:`poll` — no wait; with
    every query of the ring still in flight the slice goes unmeasured (``dropped``). Queries come
    from the context's :func:`~atmos.gpu.queries.query_pool`: at most ``depth`` are made.
    """

    DEPTH = 16

    def __init__(self, ctx, late: bool = True, depth: int = DEPTH):
        self.pool = query_pool(ctx)
        self.late = late
        self.depth = depth
        self.dropped = 0
        self._pending: deque = deque()       # (query, done) in the order issued
        self._spare: list = []               # queries of the ring not in flight

    def __call__(self, run: Callable[[], None]) -> float:
        query = self.pool.timer()
        try:
            query.begin()
            try:
                run()
            finally:
                query.end()
            return query.result()
        finally:
            self.pool.release(query)

    def submit(self, run: Callable[[], None], done: Callable[[float], None]) -> None:
        """Run the slice in a timer query; ``done(ms)`` once its result is in (never waits)."""
        self.poll()
        if self._spare:
            query = self._spare.pop()
        elif len(self._pending) < self.depth:
            query = self.pool.timer()
        else:
            self.dropped += 1
            run()
            return
        query.begin()
        try:
            run()
        finally:
            query.end()
            query.flush()
            self._pending.append((query, done))

    def poll(self) -> None:
        """Hand the results that came in to their ``done``, oldest first; never waits."""
        while self._pending:
            query, done = self._pending[0]
            ms = query.poll()
            if ms is None:
                return
            self._pending.popleft()
            self._spare.append(query)
            done(ms)

    def release(self) -> None:
        """Give the ring's queries back to the pool (their results are dropped)."""
        for query in self._spare + [query for query, _ in self._pending]:
            self.pool.release(query)
        self._spare.clear()
        self._pending.clear()


def timer_query_measure(ctx, late: bool = True) -> TimerQueryMeasure:
    """A :class:`TimerQueryMeasure` of ``ctx``: read without waiting by a SlicedJob when ``late``,
    at once (waiting) otherwise."""
    return TimerQueryMeasure(ctx, late)


def gpu_measure(ctx) -> Measure:
    """The best GPU-cost measure for ``ctx``: timer queries on a real GPU (read late by a job, without
    waiting), synced wall time on a software rasterizer (llvmpipe reports meaningless timer-query results)."""
    return synced_measure(ctx) if is_software(ctx) else timer_query_measure(ctx)


@dataclass
class SliceContext:
    """What a slice sees: where to write (``target`` = C), what to read (``previous`` = B), which slice."""

    job: "SlicedJob"
    step: int                 # index of the step being computed (0 for the first)
    task: "SliceTask"
    slice: int                # index of this slice inside its task
    slices: int               # number of slices of this task in this step
    target: TextureSet        # triple.c, being written
    previous: TextureSet      # triple.b, the newest completed result (read only)
    state: dict               # the job's scratch space, kept across slices and steps

    @property
    def gpu(self):
        return self.job.triple.gpu


class SliceTask:
    """One task of a chain: ``slices`` pieces of work (an int, or a callable asked at the start of each step).

    ``run(slice_index, job_ctx)`` does one slice, writing into ``job_ctx.target``.
    """

    def __init__(self, name: str, slices: int | Callable[[], int], run: Callable[[int, SliceContext], None]):
        _check_name("task", name)
        if not callable(run):
            raise ValueError(f"task {name!r}: run must be callable as run(slice_index, job_ctx); got {run!r}")
        if not callable(slices):
            _check_count(name, slices)
        self.name = name
        self.slices = slices
        self.run = run

    def count(self) -> int:
        """This step's number of slices."""
        return _check_count(self.name, self.slices() if callable(self.slices) else self.slices)

    def __repr__(self) -> str:
        return f"SliceTask({self.name!r}, slices={self.slices!r})"


def _check_name(what: str, name) -> None:
    if not isinstance(name, str) or not name:
        raise ValueError(f"a {what} name must be a non-empty string (it keys the stats), got {name!r}")


def _check_count(name: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"task {name!r}: slices must be an int >= 0 (or a callable returning one); got {value!r}")
    return value


@dataclass
class JobStats:
    """Counters for one job; the scheduler resets the per-frame ones at each tick."""

    slices_last_frame: int = 0
    ms_last_frame: float = 0.0
    steps: int = 0
    slices_total: int = 0
    ms_total: float = 0.0
    slices_measured: int = 0                      # slices whose cost came in (late measures: fewer)
    task_ms: dict = field(default_factory=dict)   # task name → moving average of its slice cost (ms)

    @property
    def mean_slice_ms(self) -> float:
        return self.ms_total / self.slices_measured if self.slices_measured else 0.0


class SlicedJob:
    """A chain of sliced tasks writing into ``triple.c``; see the module docstring.

    ``begin(step)`` is called before the first slice of each step, with the index of the step about
    to be computed (equal to the number of completed steps), to advance simulation parameters.
    """

    EMA = 0.25  # weight of the newest sample in the per-task cost estimate

    def __init__(self, name: str, tasks: list[SliceTask], triple: TripleSet,
                 begin: Callable[[int], None] | None = None):
        _check_name("job", name)
        if begin is not None and not callable(begin):
            raise ValueError(f"job {name!r}: begin must be None or callable as begin(step); got {begin!r}")
        if not tasks:
            raise ValueError(f"job {name!r} needs at least one SliceTask; got none")
        for task in tasks:
            if not isinstance(task, SliceTask):
                raise ValueError(f"job {name!r}: tasks must be SliceTask objects; got {task!r}")
        self.name = name
        self.tasks = list(tasks)
        self.triple = triple
        self.begin = begin
        self.step = 0
        self.state: dict = {}
        self.stats = JobStats()
        self._plan: list[int] | None = None   # slices per task of the current step, fixed when it begins
        self._total = 0
        self._done = 0
        self._task = 0                        # cursor: task index and slice inside it
        self._slice = 0

    # -- progress ---------------------------------------------------------------------------
    @property
    def slices_in_step(self) -> int:
        """Slices of the current step (fixed when it begins; the tasks' current counts before that)."""
        return self._total if self._plan is not None else sum(task.count() for task in self.tasks)

    @property
    def slices_left(self) -> int:
        """Slices until the current step completes (the last of them rotates the triple)."""
        return self._total - self._done if self._plan is not None else self.slices_in_step

    @property
    def slices_done(self) -> int:
        return self._done

    @property
    def progress(self) -> float:
        """Slices done / slices in this step, in [0, 1): also the interpolation factor between A and B."""
        return self._done / self._total if self._plan is not None and self._total else 0.0

    @property
    def ready(self) -> bool:
        """True once two steps are complete, so that A and B both hold results (see :meth:`prime`)."""
        return self.step >= 2

    @property
    def next_task(self) -> SliceTask:
        """The task the next slice belongs to."""
        if self._plan is None:
            return next((s for s in self.tasks if s.count() > 0), self.tasks[0])
        return self.tasks[self._task]

    def view(self) -> tuple[TextureSet, TextureSet, float]:
        """(A, B, t) for readers: draw mix(A, B, t). Never returns C."""
        return self.triple.a, self.triple.b, self.progress

    # -- running ----------------------------------------------------------------------------
    def _begin_step(self) -> None:
        if self.begin is not None:
            self.begin(self.step)
        plan = [task.count() for task in self.tasks]
        total = sum(plan)
        if total == 0:
            raise ValueError(f"job {self.name!r}: step {self.step} has no slices (every task returned 0); "
                             "a step needs at least one slice to write texture set C")
        self._plan, self._total, self._done = plan, total, 0
        self._task, self._slice = 0, 0
        while self._plan[self._task] == 0:
            self._task += 1

    def _run_one(self, measure: Measure) -> None:
        if self._plan is None:
            self._begin_step()
        task = self.tasks[self._task]
        job_ctx = SliceContext(self, self.step, task, self._slice, self._plan[self._task],
                               self.triple.c, self.triple.b, self.state)

        def run() -> None:
            task.run(job_ctx.slice, job_ctx)

        stats = self.stats
        if getattr(measure, "late", False):   # the cost comes in later; this frame counts the estimate
            estimate = self.expected_slice_ms(task) or 0.0
            measure.submit(run, lambda ms, name=task.name: self._measured(name, ms))
            ms = estimate
        else:
            ms = measure(run)
            self._measured(task.name, ms)
        stats.slices_last_frame += 1
        stats.ms_last_frame += ms
        stats.slices_total += 1

        self._done += 1
        self._slice += 1
        while self._task < len(self._plan) and self._slice >= self._plan[self._task]:
            self._task += 1
            self._slice = 0
        if self._done >= self._total:
            self.triple.rotate()
            self.step += 1
            self.stats.steps = self.step
            self._plan = None
            self._done = self._total = 0
            self._task = self._slice = 0

    def run_slices(self, n: int, *, measure: Measure | None = None) -> int:
        """Run ``n`` slices (crossing into the next step when one completes); returns the slices run.

        When the last slice of a step finishes: ``triple.rotate()``, ``step += 1``, progress back to 0.
        ``measure`` times each slice (default: :func:`perf_measure`, no GPU sync).
        """
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise ValueError(f"run_slices(n): n must be an int >= 0; got {n!r}")
        measure = measure or perf_measure
        for _ in range(n):
            self._run_one(measure)
        return n

    def run_step(self, *, measure: Measure | None = None) -> None:
        """Run every remaining slice of the current step now (naive mode); ends with a rotation."""
        measure = measure or perf_measure
        step = self.step
        while self.step == step:
            self._run_one(measure)

    def prime(self, *, measure: Measure | None = None) -> None:
        """Run whole steps until two are complete, so A and B both hold results before the first frame."""
        while self.step < 2:
            self.run_step(measure=measure)

    def _measured(self, task_name: str, ms: float) -> None:
        stats = self.stats
        stats.ms_total += ms
        stats.slices_measured += 1
        previous = stats.task_ms.get(task_name)
        stats.task_ms[task_name] = ms if previous is None else previous + self.EMA * (ms - previous)

    def expected_slice_ms(self, task: SliceTask | None = None) -> float | None:
        """Estimated cost of the next slice (or one of ``task``) from its task's measured costs
        (None before any measurement)."""
        estimate = self.stats.task_ms.get((task or self.next_task).name)
        if estimate is None and self.stats.slices_measured:
            estimate = self.stats.mean_slice_ms
        return estimate

    def release(self) -> None:
        self.triple.release()

    def __repr__(self) -> str:
        return f"SlicedJob({self.name!r}, step={self.step}, progress={self.progress:.3f})"
