"""A census of live OpenGL objects: how many of each kind were made and not released.

``with GLCensus() as census:`` wraps moderngl's object-making methods (``ctx.texture``,
``ctx.buffer``, ``ctx.framebuffer``, ``ctx.query``, ...; every context in the process) while the block
runs; :meth:`GLCensus.live` counts, per kind, the objects made since then that are still alive (not
released, their context not released). A soak compares it over time (0 growth: nothing leaks), a
lifetime test after ``App.close``. Queries have no release in moderngl: they count as live, which is
what the query recycler keeps flat. Censuses do not nest; every wrapped call runs and returns as before.
"""
from __future__ import annotations

from collections import Counter

import moderngl

MAKERS = ("texture", "texture3d", "texture_array", "texture_cube", "depth_texture", "depth_texture_cube",
          "external_texture", "buffer", "framebuffer", "simple_framebuffer", "renderbuffer",
          "depth_renderbuffer", "vertex_array", "simple_vertex_array", "program", "compute_shader", "sampler",
          "query", "scope")


def _released(obj) -> bool:
    invalid = moderngl.InvalidObject if hasattr(moderngl, "InvalidObject") else type(None)
    ctx = getattr(obj, "ctx", None)
    return isinstance(getattr(obj, "mglo", None), invalid) or (ctx is not None and isinstance(ctx.mglo, invalid))


class GLCensus:
    """Records every moderngl object made while installed; see the module docstring."""

    def __init__(self):
        self._made: list = []
        self._saved: list = []

    def __enter__(self) -> "GLCensus":
        if self._saved:
            raise RuntimeError("GLCensus is already installed; censuses do not nest")
        for name in MAKERS:
            original = moderngl.Context.__dict__.get(name)
            if original is not None:
                self._saved.append((name, original))
                setattr(moderngl.Context, name, self._wrap(original))
        return self

    def __exit__(self, *exc) -> None:
        for name, original in reversed(self._saved):
            setattr(moderngl.Context, name, original)
        self._saved.clear()

    def _wrap(self, original):
        made = self._made

        def wrapped(ctx, *args, **kwargs):
            obj = original(ctx, *args, **kwargs)
            made.append(obj)
            return obj

        wrapped.__name__ = original.__name__
        wrapped.__doc__ = original.__doc__
        return wrapped

    def live(self, ctx=None) -> Counter:
        """Kind (class name) -> objects made since the census began that are alive now (of ``ctx``
        only, when given). Forgets the released ones, so a long soak stays small."""
        self._made[:] = [obj for obj in self._made if not _released(obj)]
        return Counter(type(obj).__name__ for obj in self._made if ctx is None or obj.ctx is ctx)

    def total(self, ctx=None) -> int:
        """All live objects of :meth:`live`, summed."""
        return sum(self.live(ctx).values())
