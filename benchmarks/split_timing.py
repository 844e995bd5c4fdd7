"""GPU time and Python time of queued work, apart: a timer query around a backlog of runs (what the GPU
spends), the time to issue them (what Python spends) and the wall time from glFinish to glFinish."""
from __future__ import annotations

import time

from atmos.gpu.queries import query_pool


def split_time(ctx, run, count: int) -> dict:
    """Run ``run()`` once untimed (compiles, uploads), then ``count`` times queued back to back: ms per
    run on the GPU (``gpu_ms``, one GL_TIME_ELAPSED query around the backlog), issuing them in Python
    (``python_ms``; a driver that runs work while it is issued, as Mesa's llvmpipe may, counts it here
    too) and wall clock (``wall_ms``, glFinish before and after)."""
    pool = query_pool(ctx)
    query = pool.timer()
    try:
        run()
        ctx.finish()
        start = time.perf_counter()
        query.begin()
        for _ in range(count):
            run()
        issued = time.perf_counter()
        query.end()
        ctx.finish()
        end = time.perf_counter()
        gpu = query.result()
    finally:
        pool.release(query)
    return {"gpu_ms": gpu / count, "python_ms": (issued - start) * 1e3 / count, "wall_ms": (end - start) * 1e3 / count}
