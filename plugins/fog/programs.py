"""Compiled fog programs for a GpuContext (its own cache) or a plain moderngl context (a cache per context)."""
from __future__ import annotations

import weakref

from atmos.gpu.shaders import build_program

_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def gl_context(target):
    """The moderngl context of a GpuContext, or ``target`` itself."""
    return getattr(target, "ctx", target)


def program(target, defines: dict | None = None, **stages: str):
    """``target.program(...)`` for a GpuContext; a per-context cached build_program for moderngl."""
    if hasattr(target, "program") and hasattr(target, "ctx"):
        return target.program(defines=defines, **stages)
    cache = _CACHE.setdefault(target, {})
    key = (tuple(sorted(stages.items())), tuple(sorted((defines or {}).items())))
    if key not in cache:
        cache[key] = build_program(target, stages, defines)
    return cache[key]
