"""OpenGL query objects per moderngl context: timer queries read without waiting, and a recycler.

:class:`TimerQuery` is a ``GL_TIME_ELAPSED`` query of atmos's own (moderngl's Query can neither say
whether its result is in nor be deleted): :meth:`TimerQuery.poll` asks ``GL_QUERY_RESULT_AVAILABLE``
first and never waits. The GL functions come from ``eglGetProcAddress`` when an EGL context is current,
else ``glXGetProcAddressARB``; where neither resolves, a moderngl Query read one poll late stands in.

moderngl 5.13 has no ``Query.release``, so every user of queries takes them from the context's
:class:`QueryPool` and gives them back when done; Apps created and closed one after another on one
context reuse the same queries instead of leaking new ones.
"""
from __future__ import annotations

import ctypes
import weakref
from functools import lru_cache

_POOLS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()  # moderngl.Context -> QueryPool

GL_TIME_ELAPSED = 0x88BF
GL_QUERY_RESULT = 0x8866
GL_QUERY_RESULT_AVAILABLE = 0x8867
TIMER = "timer"                                     # QueryPool kind of a TimerQuery

_GLuint_p, _GLint_p, _GLuint64_p = (ctypes.POINTER(t) for t in (ctypes.c_uint, ctypes.c_int, ctypes.c_uint64))
_SIGNATURES = {
    "glGenQueries": (ctypes.c_int, _GLuint_p),
    "glDeleteQueries": (ctypes.c_int, _GLuint_p),
    "glBeginQuery": (ctypes.c_uint, ctypes.c_uint),
    "glEndQuery": (ctypes.c_uint,),
    "glGetQueryObjectiv": (ctypes.c_uint, ctypes.c_uint, _GLint_p),
    "glGetQueryObjectui64v": (ctypes.c_uint, ctypes.c_uint, _GLuint64_p),
    "glFlush": (),
}
_LOADED: dict = {}                                   # "egl" / "glx" -> _GL or None


class _GL:
    """The query functions of the current context's API."""

    def __init__(self, get_proc):
        for name, args in _SIGNATURES.items():
            address = get_proc(name.encode())
            if not address:
                raise OSError(f"{name} did not resolve")
            setattr(self, name[2:], ctypes.CFUNCTYPE(None, *args)(address))


@lru_cache(maxsize=2)
def _loader(api: str):
    """(is a context current, get_proc) of ``api``, loaded once per process; raises OSError where its
    library is missing."""
    if api == "egl":
        lib = _library("libEGL.so.1", "libEGL.so")
        current, get_proc = lib.eglGetCurrentContext, lib.eglGetProcAddress
    else:
        lib = _library("libGL.so.1", "libGL.so")
        current, get_proc = lib.glXGetCurrentContext, lib.glXGetProcAddressARB
    current.restype, current.argtypes = ctypes.c_void_p, []
    get_proc.restype, get_proc.argtypes = ctypes.c_void_p, [ctypes.c_char_p]
    return current, get_proc


def _library(*names):
    for name in names:
        try:
            return ctypes.CDLL(name)
        except OSError:
            continue
    raise OSError(f"none of {names} loads")


def _current_api():
    """(api, get_proc) of the API (EGL or GLX) with a context current in this thread, or None."""
    for api in ("egl", "glx"):
        try:
            current, get_proc = _loader(api)
            if current():
                return api, get_proc
        except (OSError, AttributeError):
            continue
    return None


def gl_functions():
    """The query functions for the context current in this thread (EGL or GLX), or None where
    neither API has a current context or the functions do not resolve."""
    found = _current_api()
    if found is None:
        return None
    api, get_proc = found
    if api not in _LOADED:
        try:
            _LOADED[api] = _GL(get_proc)
        except OSError:
            _LOADED[api] = None
    return _LOADED[api]


class TimerQuery:
    """One ``GL_TIME_ELAPSED`` query: :meth:`begin`, :meth:`end`, then :meth:`poll` (milliseconds, or
    None while the GPU has not finished) or :meth:`result` (waits). Time queries do not nest."""

    __slots__ = ("_gl", "glo")

    def __init__(self, gl: _GL):
        self._gl = gl
        name = ctypes.c_uint(0)
        gl.GenQueries(1, ctypes.byref(name))
        self.glo = name.value

    def begin(self) -> None:
        self._gl.BeginQuery(GL_TIME_ELAPSED, self.glo)

    def end(self) -> None:
        self._gl.EndQuery(GL_TIME_ELAPSED)

    def flush(self) -> None:
        """Send the queued commands on (``glFlush``), so an ended query's result comes in eventually."""
        self._gl.Flush()

    def poll(self) -> float | None:
        """The measured milliseconds if the result is in, else None; never waits."""
        available = ctypes.c_int(0)
        self._gl.GetQueryObjectiv(self.glo, GL_QUERY_RESULT_AVAILABLE, ctypes.byref(available))
        return self._read() if available.value else None

    def result(self) -> float:
        """The measured milliseconds; waits for the GPU when it has not finished."""
        return self._read()

    def _read(self) -> float:
        ns = ctypes.c_uint64(0)
        self._gl.GetQueryObjectui64v(self.glo, GL_QUERY_RESULT, ctypes.byref(ns))
        return ns.value / 1e6

    def delete(self) -> None:
        """Delete the GL query (its context must be current); later calls do nothing."""
        if self.glo:
            name = ctypes.c_uint(self.glo)
            self._gl.DeleteQueries(1, ctypes.byref(name))
            self.glo = 0


class ModernglTimerQuery:
    """:class:`TimerQuery`'s interface over a moderngl Query, where GL's functions do not resolve:
    availability is unknown, so :meth:`poll` gives None the first time after :meth:`end` and the
    result (which may wait) the next time."""

    __slots__ = ("query", "_polls")

    def __init__(self, query):
        self.query = query
        self._polls = 0

    def begin(self) -> None:
        self.query.__enter__()

    def end(self) -> None:
        self.query.__exit__(None, None, None)
        self._polls = 0

    def flush(self) -> None:
        pass

    def poll(self) -> float | None:
        self._polls += 1
        return self.query.elapsed / 1e6 if self._polls > 1 else None

    def result(self) -> float:
        return self.query.elapsed / 1e6

    def delete(self) -> None:
        """moderngl 5.13 cannot delete a Query; the pool keeps it for reuse instead."""


class QueryPool:
    """Spare query objects of one moderngl context, by kind.

    :meth:`timer` hands out a :class:`TimerQuery` (spare or new); :meth:`acquire` a moderngl query
    of the asked kind (``time=True`` by default); :meth:`release` takes either back. ``made`` counts
    queries ever created through this pool, ``spare`` those free now. Get the context's pool with
    :func:`query_pool` (``GpuContext.queries`` is the same object).
    """

    def __init__(self, ctx):
        self._ctx = weakref.ref(ctx)  # the registry is keyed by ctx: a strong ref would keep it alive
        self.made = 0
        self._spare: dict = {}                  # kind -> [query]
        self._out: dict[int, tuple] = {}        # id(query) -> (kind, query), handed out
        self._cleared = False

    @staticmethod
    def _kind(time: bool, samples: bool, any_samples: bool, primitives: bool):
        kind = (bool(time), bool(samples), bool(any_samples), bool(primitives))
        if not any(kind):
            raise ValueError("QueryPool.acquire: ask for at least one of time, samples, any_samples, primitives")
        return kind

    def _context(self):
        ctx = self._ctx()
        if ctx is None:
            raise RuntimeError("QueryPool: the moderngl context of this pool is gone")
        return ctx

    def _new(self, kind):
        """A new query of ``kind`` on the pool's context (which must be current)."""
        ctx = self._context()
        if kind == TIMER:
            gl = gl_functions()
            return TimerQuery(gl) if gl is not None else ModernglTimerQuery(ctx.query(time=True))
        return ctx.query(time=kind[0], samples=kind[1], any_samples=kind[2], primitives=kind[3])

    def _take(self, kind):
        spare = self._spare.get(kind)
        if spare:
            query = spare.pop()
        else:
            query = self._new(kind)
            self.made += 1
            self._cleared = False
        self._out[id(query)] = (kind, query)
        return query

    def timer(self) -> TimerQuery | ModernglTimerQuery:
        """A timer query read without waiting (:meth:`TimerQuery.poll`), until :meth:`release`."""
        return self._take(TIMER)

    def acquire(self, *, time: bool = True, samples: bool = False, any_samples: bool = False,
                primitives: bool = False):
        """A moderngl query of this kind (``ctx.query(time=..., ...)``), spare or new, until :meth:`release`."""
        return self._take(self._kind(time, samples, any_samples, primitives))

    def release(self, query) -> None:
        """Take ``query`` back for the next request of its kind (it must not be running)."""
        entry = self._out.pop(id(query), None)
        if entry is None and self._cleared:
            return  # the context was released first (App.close after GpuContext.release): nothing to keep
        if entry is None:
            raise ValueError("QueryPool.release: this query was not acquired from this pool, or was "
                             "already released")
        self._spare.setdefault(entry[0], []).append(query)

    @property
    def spare(self) -> int:
        """Queries free for reuse now."""
        return sum(len(queries) for queries in self._spare.values())

    @property
    def in_use(self) -> int:
        """Queries acquired and not yet released."""
        return len(self._out)

    def clear(self) -> None:
        """Forget every query (spare and handed out), deleting those that can be deleted; for when
        the context itself is released (it must be current)."""
        queries = [q for spare in self._spare.values() for q in spare] + [q for _, q in self._out.values()]
        for query in queries:
            delete = getattr(query, "delete", None) or getattr(query, "release", None)  # no Query.release in 5.13
            if delete is not None:
                delete()
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


GL_SYNC_GPU_COMMANDS_COMPLETE = 0x9117
GL_ALREADY_SIGNALED, GL_CONDITION_SATISFIED = 0x911A, 0x911C
_SYNC: dict = {}                                     # api -> (FenceSync, ClientWaitSync, DeleteSync) or None


def _sync_functions():
    """glFenceSync, glClientWaitSync and glDeleteSync of the current context's API, or None."""
    found = _current_api()
    if found is None:
        return None
    api, get_proc = found
    if api not in _SYNC:
        names = [get_proc(n) for n in (b"glFenceSync", b"glClientWaitSync", b"glDeleteSync")]
        _SYNC[api] = None if not all(names) else (
            ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_uint, ctypes.c_uint)(names[0]),
            ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_void_p, ctypes.c_uint, ctypes.c_uint64)(names[1]),
            ctypes.CFUNCTYPE(None, ctypes.c_void_p)(names[2]))
    return _SYNC[api]


class Fence:
    """A GL fence after the commands queued so far: :meth:`done` says, never waiting, whether the GPU has
    finished them (a buffer they wrote can then be read without a stall). Where the sync functions do not
    resolve, done() is True the second time it is asked."""

    __slots__ = ("_fns", "_sync", "_asked")

    def __init__(self):
        self._fns = _sync_functions()
        self._sync = self._fns[0](GL_SYNC_GPU_COMMANDS_COMPLETE, 0) if self._fns else None
        self._asked = 0

    def done(self) -> bool:
        if self._sync is None:
            self._asked += 1
            return self._asked > 1
        status = self._fns[1](self._sync, 0, 0)
        if status in (GL_ALREADY_SIGNALED, GL_CONDITION_SATISFIED):
            self.delete()
            return True
        return False

    def delete(self) -> None:
        """Delete the GL sync object (its context must be current); later calls do nothing."""
        if self._sync is not None:
            self._fns[2](self._sync)
            self._sync = None
            self._asked = 1
