"""A meter of moderngl calls: how many, how long, and which of them bring data back to the CPU.

``with GLMeter() as meter:`` wraps moderngl's methods (for every context in the process) while the
block runs and records, per call kind:

* ``work`` — calls that hand the GPU work (draws, dispatches, clears, copies, uploads): on a
  software rasterizer their time is the GPU's time, so *Python time = wall time - work time -
  readback time* is what a frame costs the CPU without the GPU (benchmarks/bench_python_frame.py);
* ``readback`` — calls that make the CPU wait for GPU results: reads of textures, buffers and
  framebuffers into memory, a moderngl timer query's ``elapsed``, :meth:`TimerQuery.result
  <atmos.gpu.queries.TimerQuery.result>` and ``ctx.finish()``; each is recorded with the atmos
  source line that made it (``meter.readbacks``), so a test can say exactly which ones a frame
  makes. A ``read_into`` a moderngl Buffer (a pixel-buffer copy, asynchronous) is work;
* ``state`` — uniform writes (``Uniform.write``), counted: ``meter.uniform_writes``;
* ``query`` — atmos's own timer queries begun (``TimerQuery.begin``) and polled
  (``TimerQuery.poll``: the result only once it is in, so no wait) are counted, not readbacks.

Times come from ``clock`` (default ``time.perf_counter``; ``time.thread_time`` gives the calling
thread's CPU time, which leaves out waits and other processes). Nothing else changes: every
wrapped call runs and returns as before — unless ``stub_work`` is set: then the work calls are
counted but not made (no draw, dispatch, clear or upload reaches the driver; state changes,
readbacks and queries still do), which is how a benchmark times the CPU side of a frame as if
the GPU were infinitely fast. Meters do not nest.
"""
from __future__ import annotations

import os
import sys
import time
from collections import Counter
from dataclasses import dataclass, field
from typing import Callable

import moderngl

from atmos.gpu.queries import TimerQuery

_TEXTURES = ("Texture", "Texture3D", "TextureArray", "TextureCube")
WORK = {
    "VertexArray": ("render", "render_indirect", "transform"),
    "ComputeShader": ("run", "run_indirect"),
    "Framebuffer": ("clear",),
    "Context": ("clear", "copy_framebuffer", "copy_buffer"),
    "Buffer": ("write", "clear", "orphan"),
    **{name: ("write", "build_mipmaps") for name in _TEXTURES},
}
READBACK = {
    "Buffer": ("read", "read_into", "read_chunks", "read_chunks_into"),
    "Framebuffer": ("read", "read_into"),
    "Context": ("finish",),
    **{name: ("read", "read_into") for name in _TEXTURES},
}
READBACK_PROPERTIES = {"Query": ("elapsed",)}
STATE = {"Uniform": ("write",)}      # counted (uniform writes: ``meter.uniform_writes``), never stubbed
OWN = {TimerQuery: {"begin": "query", "poll": "query", "result": "readback"}}
_PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))   # atmos/
_ROOT = os.path.dirname(_PACKAGE)


@dataclass
class Readback:
    """One GPU→CPU wait: ``call`` ("Texture.read", "Query.elapsed", ...) made from ``path`` line
    ``line``, the nearest caller outside moderngl and this module; ``where`` is ``path:line`` with
    the path relative to the project."""
    call: str
    path: str
    line: int

    @property
    def where(self) -> str:
        return f"{_shown(self.path)}:{self.line}"


@dataclass
class GLMeter:
    """Counts and times moderngl calls while installed; see the module docstring."""
    calls: Counter = field(default_factory=Counter)          # "Class.method" -> calls
    seconds: Counter = field(default_factory=Counter)        # "work" / "readback" -> seconds inside
    readbacks: list = field(default_factory=list)            # Readback, in call order
    clock: Callable[[], float] = time.perf_counter
    stub_work: bool = False
    _saved: list = field(default_factory=list, repr=False)

    @property
    def work_s(self) -> float:
        return self.seconds["work"]

    @property
    def readback_s(self) -> float:
        return self.seconds["readback"]

    @property
    def uniform_writes(self) -> int:
        """Uniform values written (``Uniform.write``: every ``.value =`` and ``write_uniforms`` write)."""
        return self.calls["Uniform.write"]

    def reset(self) -> None:
        """Forget what was recorded so far (the meter stays installed)."""
        self.calls.clear()
        self.seconds.clear()
        self.readbacks.clear()

    def readback_counts(self) -> Counter:
        """(call, where) -> how often, over what was recorded."""
        return Counter((r.call, r.where) for r in self.readbacks)

    # -- installing -------------------------------------------------------------------------
    def __enter__(self) -> "GLMeter":
        if self._saved:
            raise RuntimeError("GLMeter is already installed; meters do not nest")
        for table, kind in ((WORK, "work"), (READBACK, "readback"), (STATE, "state")):
            for cls_name, methods in table.items():
                cls = getattr(moderngl, cls_name, None)
                for method in methods:
                    original = cls.__dict__.get(method) if cls is not None else None
                    if original is None or isinstance(original, property):
                        continue
                    self._saved.append((cls, method, original))
                    setattr(cls, method, self._wrap(original, f"{cls_name}.{method}", kind))
        for cls_name, names in READBACK_PROPERTIES.items():
            cls = getattr(moderngl, cls_name)
            for name in names:
                original = cls.__dict__[name]
                self._saved.append((cls, name, original))
                getter = self._wrap(original.fget, f"{cls_name}.{name}", "readback")
                setattr(cls, name, property(getter, original.fset, original.fdel, original.__doc__))
        for cls, methods in OWN.items():
            for method, kind in methods.items():
                original = cls.__dict__[method]
                self._saved.append((cls, method, original))
                setattr(cls, method, self._wrap(original, f"{cls.__name__}.{method}", kind))
        return self

    def __exit__(self, *exc) -> None:
        for cls, name, original in reversed(self._saved):
            setattr(cls, name, original)
        self._saved.clear()

    def _wrap(self, original, label: str, kind: str):
        calls, seconds, readbacks, clock = self.calls, self.seconds, self.readbacks, self.clock
        if kind == "work" and self.stub_work:
            def stubbed(obj, *args, **kwargs):
                calls[label] += 1
            stubbed.__name__ = getattr(original, "__name__", label)
            return stubbed

        def wrapped(obj, *args, **kwargs):
            actual = kind
            if kind == "readback" and label.endswith("read_into") and isinstance(
                    args[0] if args else kwargs.get("buffer"), moderngl.Buffer):
                actual = "work"                  # a copy into a pixel buffer: queued, not waited for
            start = clock()
            try:
                return original(obj, *args, **kwargs)
            finally:
                seconds[actual] += clock() - start
                calls[label] += 1
                if actual == "readback":
                    readbacks.append(Readback(label, *_caller()))

        wrapped.__name__ = getattr(original, "__name__", label)
        wrapped.__doc__ = getattr(original, "__doc__", None)
        return wrapped


_SKIP = (os.path.abspath(__file__), os.path.dirname(moderngl.__file__))


def _caller() -> tuple[str, int]:
    """(file, line) of the innermost frame outside moderngl and this module (cheap: per readback)."""
    frame = sys._getframe(2)
    while frame is not None:
        path = frame.f_code.co_filename
        if not path.startswith(_SKIP) and "moderngl" not in path:
            return path, frame.f_lineno
        frame = frame.f_back
    return "?", 0


def _shown(path: str) -> str:
    path = os.path.abspath(path)
    return os.path.relpath(path, _ROOT) if path.startswith(_ROOT + os.sep) else path


def count_calls(run: Callable[[], object]) -> tuple[int, int]:
    """(Python, C) function calls made while ``run()`` runs (``sys.setprofile``; their sum is what
    cProfile's total counts): tests/test_frame_budget.py and benchmarks/bench_python_frame.py."""
    counts = {"call": 0, "c_call": 0}

    def count(frame, event, arg):
        if event in counts:
            counts[event] += 1
    sys.setprofile(count)
    try:
        run()
    finally:
        sys.setprofile(None)
    return counts["call"], counts["c_call"]
