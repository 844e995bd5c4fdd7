"""Hands out each frame's slices of the registered :class:`~atmos.slicing.job.SlicedJob` objects.

Modes:

* ``"sliced"`` — each :meth:`FrameScheduler.tick` runs ``slices_per_frame`` slices, round robin over
  the jobs; or, with ``time_budget_ms``, as many slices as their measured cost allows (always at
  least one per frame, so progress never stalls). A job completes at most one step per tick (a
  second rotation in the same frame would throw away a result that was never shown), but after a
  rotation it goes on into the next step, so a frame that crosses a step boundary runs as many
  slices as any other and the interpolation factor t advances by the same amount every frame.
* ``"naive"`` — each tick runs a whole step of every job (the frame pays for it: the reference for
  the benchmarks).
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass

from atmos.checks import check_bool, check_choice, check_int, check_num
from atmos.slicing.job import Measure, SlicedJob, gpu_measure, perf_measure

MODES = ("sliced", "naive")


@dataclass(frozen=True)
class FrameStats:
    """One job's numbers as of the last tick."""

    slices_last_frame: int
    ms_last_frame: float
    steps: int
    mean_slice_ms: float
    progress: float


class FrameScheduler:
    """Runs one frame's worth of slices of every added job per :meth:`tick`.

    ``measure`` times one slice (a callable that runs its argument and returns milliseconds): by
    default ``time.perf_counter`` around the slice, or, when ``sync`` is true, the GPU's cost of the
    slice (:func:`~atmos.slicing.job.gpu_measure`: timer queries on a GPU, read once their results are
    in, so the budget uses each task's cost from a frame or two before; synced wall time on llvmpipe).
    ``sync`` defaults to true exactly when a time budget is in use (the budget needs the GPU cost;
    without one, syncing would only stall the pipeline).
    """

    def __init__(self, mode: str = "sliced", slices_per_frame: int = 1, time_budget_ms: float | None = None,
                 measure: Measure | None = None, sync: bool | None = None):
        self.mode = mode
        self.slices_per_frame = slices_per_frame
        self.time_budget_ms = time_budget_ms
        self.measure = measure
        self.sync = (self.time_budget_ms is not None) if sync is None else check_bool("FrameScheduler", "sync", sync)
        self.jobs: list[SlicedJob] = []
        self.frame = 0
        self.slices_last_frame = 0
        self.ms_last_frame = 0.0
        self._next = 0  # round-robin start
        self._gpu_measures: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # ctx -> Measure

    # -- settings (checked on every assignment, e.g. ``app.frames.slices_per_frame = 4``) ----------
    @property
    def mode(self) -> str:
        return self._mode

    @mode.setter
    def mode(self, value: str) -> None:
        self._mode = check_choice("FrameScheduler", "mode", value, MODES)

    @property
    def slices_per_frame(self) -> int:
        """Slices run per frame without a time budget (>= 1: 0 would stop every sliced job)."""
        return self._slices_per_frame

    @slices_per_frame.setter
    def slices_per_frame(self, value: int) -> None:
        self._slices_per_frame = check_int("FrameScheduler", "slices_per_frame", value, 1, 1_000_000)

    @property
    def time_budget_ms(self) -> float | None:
        """Milliseconds of slices per frame (always at least one slice), or None for ``slices_per_frame``."""
        return self._time_budget_ms

    @time_budget_ms.setter
    def time_budget_ms(self, value: float | None) -> None:
        self._time_budget_ms = check_num("FrameScheduler", "time_budget_ms", value, 0.0, lo_open=True, optional=True)

    @property
    def measure(self) -> Measure | None:
        return self._measure

    @measure.setter
    def measure(self, value: Measure | None) -> None:
        if value is not None and not callable(value):
            raise ValueError(f"FrameScheduler.measure must be None or a callable measure(run) -> milliseconds, "
                             f"got {value!r}")
        self._measure = value

    # -- jobs -------------------------------------------------------------------------------
    def add(self, job: SlicedJob) -> SlicedJob:
        if any(j is job for j in self.jobs):
            raise ValueError(f"job {job.name!r} is already in this FrameScheduler")
        if any(j.name == job.name for j in self.jobs):
            raise ValueError(f"a job named {job.name!r} is already in this FrameScheduler; job names must be unique "
                             f"(they key stats); present: {', '.join(j.name for j in self.jobs)}")
        self.jobs.append(job)
        return job

    def remove(self, job: SlicedJob) -> None:
        for index, present in enumerate(self.jobs):
            if present is job:
                del self.jobs[index]
                if self.jobs:
                    self._next %= len(self.jobs)
                return
        raise ValueError(f"job {getattr(job, 'name', job)!r} is not in this FrameScheduler; "
                         f"present: {', '.join(j.name for j in self.jobs) or 'none'}")

    def __contains__(self, job) -> bool:
        return any(j is job for j in self.jobs)

    # -- frames -----------------------------------------------------------------------------
    def _measure_for(self, job: SlicedJob) -> Measure:
        if self.measure is not None:
            return self.measure
        if not self.sync:
            return perf_measure
        ctx = job.triple.gpu.ctx  # one measure per context, made once: no query or GL_RENDERER read per slice
        measure = self._gpu_measures.get(ctx)
        if measure is None:
            measure = self._gpu_measures[ctx] = gpu_measure(ctx)
        return measure

    def tick(self) -> None:
        """Run one frame's worth of slices."""
        self.frame += 1
        for measure in list(self._gpu_measures.values()) + [self.measure]:
            poll = getattr(measure, "poll", None)
            if poll is not None:
                poll()                       # late timer-query results that came in since the last tick
        for job in self.jobs:
            job.stats.slices_last_frame = 0
            job.stats.ms_last_frame = 0.0
        if self.jobs:
            if self.mode == "naive":
                for job in self.jobs:
                    job.run_step(measure=self._measure_for(job))
            else:
                self._tick_sliced()
        self.slices_last_frame = sum(job.stats.slices_last_frame for job in self.jobs)
        self.ms_last_frame = sum(job.stats.ms_last_frame for job in self.jobs)

    def _tick_sliced(self) -> None:
        jobs = self.jobs[self._next:] + self.jobs[:self._next]
        self._next = (self._next + 1) % len(self.jobs)
        start_steps = {id(job): job.step for job in jobs}
        active = list(jobs)
        ran = 0
        spent = 0.0
        budget = self.time_budget_ms
        while active:
            for job in list(active):
                if job.step != start_steps[id(job)] and job.slices_left == 1:
                    active.remove(job)           # its next slice would be a second rotation this frame
                    continue
                if budget is None:
                    if ran >= self.slices_per_frame:
                        return
                elif ran:
                    expected = job.expected_slice_ms()
                    if expected is None and job.stats.slices_total and ran >= self.slices_per_frame:
                        active.remove(job)   # its costs are still on their way (a late measure)
                        continue
                    if expected is not None and spent + expected > budget:
                        active.remove(job)   # does not fit; a job with cheaper slices still may
                        continue
                before = job.stats.ms_last_frame
                job.run_slices(1, measure=self._measure_for(job))
                spent += job.stats.ms_last_frame - before
                ran += 1

    def release(self) -> None:
        """Give the queries of the timer-query measures it made back to their pools (App.close)."""
        for measure in list(self._gpu_measures.values()):
            release = getattr(measure, "release", None)
            if release is not None:
                release()
        self._gpu_measures.clear()

    @property
    def stats(self) -> dict[str, FrameStats]:
        """Per job name: slices run last frame, steps completed, mean slice ms (and ms last frame, progress)."""
        return {job.name: FrameStats(job.stats.slices_last_frame, job.stats.ms_last_frame, job.step,
                                     job.stats.mean_slice_ms, job.progress) for job in self.jobs}

    def __repr__(self) -> str:
        budget = f"time_budget_ms={self.time_budget_ms}" if self.time_budget_ms else f"slices_per_frame={self.slices_per_frame}"
        return f"FrameScheduler({self.mode!r}, {budget}, jobs={[j.name for j in self.jobs]})"
