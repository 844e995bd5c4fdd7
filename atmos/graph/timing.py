"""Per-pass GPU time queries in a small ring per pass, read only once their results are in."""
from __future__ import annotations

import time
from collections import deque
from contextlib import contextmanager

from atmos.gpu.queries import QueryPool, query_pool

RING = 4  # queries per pass: a frame whose pass has all of them still in flight goes unmeasured


class _Ring:
    __slots__ = ("queries", "pending", "current", "start")

    def __init__(self):
        self.queries: list = [None] * RING
        self.pending: deque = deque()        # (slot, cpu_ms) in the order issued, results not read yet
        self.current: int | None = None      # the slot measuring now
        self.start = 0.0


class PassTimers:
    """GPU (timer query) and CPU (``perf_counter``) time of each pass, never waiting for the GPU.

    ``results`` maps pass name -> (gpu_ms, cpu_ms) of the latest measurement whose GPU result has
    come in: each :meth:`begin` reads the pass's finished queries (``GL_QUERY_RESULT_AVAILABLE``
    first, oldest first) and measures into a free slot of its ring of ``RING`` queries; when every
    slot still waits for the GPU, that frame's pass goes unmeasured (counted in ``dropped``).
    GL time queries cannot nest: a pass must not run its own time query while timed.

    Queries come from the context's :class:`~atmos.gpu.queries.QueryPool` (``queries``; by default
    :func:`~atmos.gpu.queries.query_pool` of ``ctx``) and go back to it when a pass is forgotten,
    timing stops (:meth:`stop`) or the timers are released.
    """

    def __init__(self, ctx, queries: QueryPool | None = None):
        self.ctx = ctx
        self.queries = queries if queries is not None else query_pool(ctx)
        self.results: dict[str, tuple[float, float]] = {}
        self.dropped = 0                     # measurements skipped: the pass's ring was all in flight
        self._rings: dict[str, _Ring] = {}
        self._last = None                    # the query ended last, flushed by end_frame

    @property
    def held(self) -> int:
        """Queries held now (at most RING per timed pass)."""
        return sum(q is not None for ring in self._rings.values() for q in ring.queries)

    @contextmanager
    def measure(self, name: str):
        """Time the body as one frame of pass ``name`` (:meth:`begin` and :meth:`end` around it)."""
        self.begin(name)
        try:
            yield
        finally:
            self.end(name)

    def begin(self, name: str) -> None:
        """Read pass ``name``'s finished queries, then start this frame's measurement in a free slot."""
        ring = self._rings.get(name)
        if ring is None:
            ring = self._rings[name] = _Ring()
        self._collect(name, ring)
        busy = {slot for slot, _ in ring.pending}
        slot = next((i for i in range(RING) if i not in busy), None)
        ring.current = slot
        if slot is None:
            self.dropped += 1
            return
        query = ring.queries[slot]
        if query is None:
            query = ring.queries[slot] = self.queries.timer()
        ring.start = time.perf_counter()
        query.begin()

    def end(self, name: str) -> None:
        """End the measurement :meth:`begin` started (nothing when it skipped this frame)."""
        ring = self._rings[name]
        slot, ring.current = ring.current, None
        if slot is None:
            return
        query = ring.queries[slot]
        query.end()
        ring.pending.append((slot, (time.perf_counter() - ring.start) * 1000.0))
        self._last = query

    def end_frame(self) -> None:
        """Flush the frame's queries to the GPU (once), so their results come in without a wait."""
        if self._last is not None:
            self._last.flush()
            self._last = None

    def _collect(self, name: str, ring: _Ring) -> None:
        while ring.pending:
            slot, cpu_ms = ring.pending[0]
            gpu_ms = ring.queries[slot].poll()
            if gpu_ms is None:
                return                       # later ones finish later still
            ring.pending.popleft()
            self.results[name] = (gpu_ms, cpu_ms)

    def _give_back(self, ring: _Ring) -> None:
        for query in ring.queries:
            if query is not None:
                self.queries.release(query)

    def forget(self, name: str) -> None:
        """Drop the queries and results of pass ``name`` (removed or culled)."""
        ring = self._rings.pop(name, None)
        self.results.pop(name, None)
        if ring:
            self._give_back(ring)

    def keep_only(self, names) -> None:
        """Forget every pass not in ``names``."""
        for name in set(self._rings) | set(self.results):
            if name not in names:
                self.forget(name)

    def stop(self) -> None:
        """Give every query back to the pool, keeping the results (timing turned off)."""
        for ring in self._rings.values():
            self._give_back(ring)
        self._rings.clear()
        self._last = None

    def release(self) -> None:
        """Give every query back to the context's pool and clear the results."""
        self.stop()
        self.results.clear()
