"""Software rasterizers (Mesa llvmpipe) keep textures in host memory: make freed texture storage
go back to the system.

glibc serves blocks above its mmap threshold with ``mmap`` (returned on ``free``), but it raises
that threshold after the first large block is freed, so later texture-sized blocks come from the
heap and stay resident when a resize frees them (30 window sizes near 1280×720: RSS +45 % with the
texture pool itself flat). Fixing the threshold at 1 MiB keeps it where it is.
"""
from __future__ import annotations

import ctypes
import ctypes.util

M_MMAP_THRESHOLD = -3          # glibc's mallopt parameter
THRESHOLD_BYTES = 1 << 20
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast")


def is_software(ctx) -> bool:
    """True on a software rasterizer (llvmpipe, softpipe, swrast): timer queries mean nothing and
    textures live in host memory."""
    renderer = ctx.info.get("GL_RENDERER", "").lower()
    return any(name in renderer for name in SOFTWARE_RENDERERS)


def trim_heap() -> bool:
    """Hand the heap's free pages back to the system (glibc ``malloc_trim``): after textures of a size
    no frame uses any more were released, what the heap kept of them (blocks under the mmap threshold,
    such as a half-resolution target) stops counting as resident. False where there is no glibc."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        return bool(libc.malloc_trim(0))
    except (OSError, AttributeError):
        return False


def return_freed_textures() -> bool:
    """Fix glibc's mmap threshold (once per process is enough); False where there is no glibc."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        return bool(libc.mallopt(M_MMAP_THRESHOLD, THRESHOLD_BYTES))
    except (OSError, AttributeError):
        return False
