"""One recycler of OpenGL query objects per moderngl context.

moderngl 5.13 has no ``Query.release``: a query made with ``ctx.query(...)`` lives as long as its
context. So every user of timer queries (the render graph's per-pass timers, the frame scheduler's
timer-query measure) takes its queries from the context's :class:`QueryPool` and gives them back
when done; Apps created and closed one after another on one context then reuse the same queries
instead of leaking new ones.
"""
from __future__ import annotations

import weakref

_POOLS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # moderngl.Context -> QueryPool


class QueryPool:
    """Spare query objects of one moderngl context, by kind.

    :meth:`acquire` hands out a spare query of the asked kind (``time=True`` by default) or makes a
    new one; :meth:`release` takes it back. ``made`` counts queries ever created on the context
    through this pool, ``spare`` those free now. Get the context's pool with :func:`query_pool`
    (``GpuContext.queries`` is the same object).
    """

    def __init__(self, ctx):
        self._ctx = weakref.ref(ctx)  # the registry is keyed by ctx: a strong ref would keep it alive
        self.made = 0
        self._spare: dict[tuple[bool, bool, bool, bool], list] = {}
        self._out: dict[int, tuple[bool, bool, bool, bool]] = {}  # id(query) -> kind, handed out
        self._cleared = False

    @staticmethod
    def _kind(time: bool, samples: bool, any_samples: bool, primitives: bool):
        kind = (bool(time), bool(samples), bool(any_samples), bool(primitives))
        if not any(kind):
            raise ValueError("QueryPool.acquire: ask for at least one of time, samples, any_samples, primitives")
        return kind

    def acquire(self, *, time: bool = True, samples: bool = False, any_samples: bool = False,
                primitives: bool = False):
        """A query of this kind (``ctx.query(time=..., ...)``), spare or new, until :meth:`release`."""
        kind = self._kind(time, samples, any_samples, primitives)
        spare = self._spare.get(kind)
        if spare:
            query = spare.pop()
        else:
            ctx = self._ctx()
            if ctx is None:
                raise RuntimeError("QueryPool.acquire: the moderngl context of this pool is gone")
            query = ctx.query(time=kind[0], samples=kind[1], any_samples=kind[2], primitives=kind[3])
            self.made += 1
            self._cleared = False
        self._out[id(query)] = kind
        return query

    def release(self, query) -> None:
        """Take ``query`` back for the next :meth:`acquire` of its kind (it must not be running)."""
        kind = self._out.pop(id(query), None)
        if kind is None and self._cleared:
            return  # the context was released first (App.close after GpuContext.release): nothing to keep
        if kind is None:
            raise ValueError("QueryPool.release: this query was not acquired from this pool, or was "
                             "already released")
        self._spare.setdefault(kind, []).append(query)

    @property
    def spare(self) -> int:
        """Queries free for reuse now."""
        return sum(len(queries) for queries in self._spare.values())

    @property
    def in_use(self) -> int:
        """Queries acquired and not yet released."""
        return len(self._out)

    def clear(self) -> None:
        """Forget every query (spare and handed out), releasing those moderngl can release; for when
        the context itself is released."""
        for queries in self._spare.values():
            for query in queries:
                release = getattr(query, "release", None)  # absent in moderngl 5.13
                if release is not None:
                    release()
        self._spare.clear()
        self._out.clear()
        self._cleared = True

    def __repr__(self) -> str:
        return f"QueryPool(made={self.made}, spare={self.spare}, in_use={self.in_use})"


def query_pool(ctx) -> QueryPool:
    """The :class:`QueryPool` of moderngl context ``ctx`` (made on first use; one per context)."""
    pool = _POOLS.get(ctx)
    if pool is None:
        pool = _POOLS[ctx] = QueryPool(ctx)
    return pool
