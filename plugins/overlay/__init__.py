"""Frame-time overlay: a bar graph of recent frame times (green < 16.7 ms, yellow < 33.3 ms, red above).

Toggle with F1 in a window (``FrameTimes.visible``). The numbers are kept even when hidden, for
the window caption and for benchmarks; per-pass timings come from the render graph's timer queries.
"""
from __future__ import annotations

import time
from collections import deque

import numpy as np

from atmos.graph import PassBuilder, PassContext, RenderPass
from atmos.plugin import Plugin
from atmos.render_core import SCREEN

HISTORY = 128


class FrameTimes:
    """Wall-clock milliseconds of the last HISTORY frames."""

    def __init__(self, visible: bool = True):
        self.visible = visible
        self.ms: deque = deque([0.0] * HISTORY, maxlen=HISTORY)
        self._last: float | None = None

    def record(self) -> None:
        now = time.perf_counter()
        if self._last is not None:
            self.ms.append((now - self._last) * 1000.0)
        self._last = now

    def summary(self) -> str:
        recent = [m for m in list(self.ms)[-60:] if m > 0]
        if not recent:
            return "-- ms"
        return f"{np.median(recent):.1f} ms median, {max(recent):.1f} ms max"


def record_frame_time(app) -> None:
    app.resource(FrameTimes).record()


class OverlayPass(RenderPass):
    name = "overlay"

    def __init__(self, times: FrameTimes, size=(256, 64)):
        self.times = times
        self.size = size
        self.program = self.data = None

    def setup(self, builder: PassBuilder) -> None:
        builder.write(SCREEN)

    def prepare(self, gpu) -> None:
        self.program = gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="overlay/bars.frag")
        self.data = gpu.track(gpu.ctx.texture((HISTORY, 1), 1, dtype="f4"))
        self.data.filter = (gpu.ctx.NEAREST, gpu.ctx.NEAREST)

    def execute(self, frame: PassContext) -> None:
        if not self.times.visible:
            return
        gpu = frame.gpu
        frame.texture(SCREEN).use()
        w, h = min(self.size[0], gpu.size[0]), min(self.size[1], gpu.size[1])
        self.data.write(np.asarray(self.times.ms, np.float32).tobytes())
        self.data.use(0)
        gpu.ctx.viewport = (4, 4, w, h) if gpu.size[0] > w + 8 else (0, 0, w, h)
        gpu.ctx.enable(gpu.ctx.BLEND)
        # over the screen; its alpha stays what present wrote (1)
        gpu.ctx.blend_func = gpu.ctx.SRC_ALPHA, gpu.ctx.ONE_MINUS_SRC_ALPHA, gpu.ctx.ZERO, gpu.ctx.ONE
        frame.fullscreen(self.program)
        gpu.ctx.disable(gpu.ctx.BLEND)
        gpu.ctx.viewport = (0, 0, *gpu.size)

    def release(self) -> None:
        if self.data is not None:
            self.data.release()


class OverlayPlugin(Plugin):
    def __init__(self, visible: bool = True):
        self.times = FrameTimes(visible)

    def build(self, app) -> None:
        app.insert_resource(self.times)
        app.add_system(record_frame_time, "update", label="record_frame_time")
        if app.graph is not None:
            app.graph.add_pass(OverlayPass(self.times))
