"""Per-pass GPU time queries in a small ring, read a couple of frames late so they never stall."""
from __future__ import annotations

import time
from contextlib import contextmanager

from atmos.gpu.queries import QueryPool, query_pool

RING = 3  # queries per pass; the one read back was issued RING - 1 frames ago


class _Ring:
    __slots__ = ("queries", "cpu_ms", "pending", "frame", "start")

    def __init__(self):
        self.queries: list = [None] * RING
        self.cpu_ms = [0.0] * RING
        self.pending = [False] * RING
        self.frame = 0
        self.start = 0.0


class PassTimers:
    """GPU (``ctx.query(time=True)``) and CPU (``perf_counter``) time of each pass.

    ``results`` maps pass name -> (gpu_ms, cpu_ms) of the latest measurement whose GPU result has
    been read back; a frame's query is read ``RING - 1`` frames later, so results lag a little.
    GL time queries cannot nest: a pass must not run its own time query while timed.

    Queries come from the context's :class:`~atmos.gpu.queries.QueryPool` (``queries``; by default
    :func:`~atmos.gpu.queries.query_pool` of ``ctx``) and go back to it when a pass is forgotten or
    the timers released: moderngl 5.13 cannot release a Query, so graphs on one context share them.
    """

    def __init__(self, ctx, queries: QueryPool | None = None):
        self.ctx = ctx
        self.queries = queries if queries is not None else query_pool(ctx)
        self.results: dict[str, tuple[float, float]] = {}
        self._rings: dict[str, _Ring] = {}

    @contextmanager
    def measure(self, name: str):
        """Time the body as one frame of pass ``name`` (:meth:`begin` and :meth:`end` around it)."""
        self.begin(name)
        try:
            yield
        finally:
            self.end(name)

    def begin(self, name: str) -> None:
        """Start this frame's measurement of pass ``name`` (read back the one issued RING - 1 frames ago)."""
        ring = self._rings.get(name)
        if ring is None:
            ring = self._rings[name] = _Ring()
        slot = ring.frame % RING
        old = (ring.frame - (RING - 1)) % RING  # issued RING - 1 frames ago
        if ring.frame >= RING - 1 and ring.pending[old]:
            self._collect(name, ring, old)
        if ring.pending[slot]:  # only when RING == 1; kept for safety
            self._collect(name, ring, slot)
        query = ring.queries[slot]
        if query is None:
            query = ring.queries[slot] = self.queries.acquire(time=True)
        ring.start = time.perf_counter()
        query.__enter__()

    def end(self, name: str) -> None:
        """End the measurement :meth:`begin` started."""
        ring = self._rings[name]
        slot = ring.frame % RING
        ring.queries[slot].__exit__(None, None, None)
        ring.cpu_ms[slot] = (time.perf_counter() - ring.start) * 1000.0
        ring.pending[slot] = True
        ring.frame += 1

    def _collect(self, name: str, ring: _Ring, slot: int) -> None:
        self.results[name] = (ring.queries[slot].elapsed / 1e6, ring.cpu_ms[slot])
        ring.pending[slot] = False

    def forget(self, name: str) -> None:
        """Drop the queries and results of pass ``name`` (removed or culled)."""
        ring = self._rings.pop(name, None)
        self.results.pop(name, None)
        if ring:
            for query in ring.queries:
                if query is not None:
                    self.queries.release(query)

    def keep_only(self, names) -> None:
        """Forget every pass not in ``names``."""
        for name in set(self._rings) | set(self.results):
            if name not in names:
                self.forget(name)

    def release(self) -> None:
        """Give every query back to the context's pool and clear the results."""
        for name in list(self._rings):
            self.forget(name)
        self.results.clear()
