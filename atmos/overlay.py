"""Frame-time overlay: a bar graph of recent frame times (green < 16.7 ms, yellow < 33.3 ms, red above).

F1 shows or hides it (its own system reads :class:`atmos.Input`; or ``OverlayPlugin.configure(visible=...)``).
The frame times are kept even when hidden, for the window caption and for benchmarks. While the
bars show, the overlay asks the render graph for per-pass timings (``graph.want_timings``; the window
caption lists the slowest passes); hidden, it stops asking and frames make no timer queries.
"""
from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass

import numpy as np

from atmos.checks import CheckedSettings, bool_field, check_int
from atmos.graph import FullscreenPass, PassBuilder, PassContext
from atmos.input import Input
from atmos.keys import key
from atmos.plugin import Plugin
from atmos.render_core import SCREEN
from atmos.gpu.uniforms import bind_textures

HISTORY = 128


@dataclass(frozen=True)
class OverlaySettings(CheckedSettings):
    """The frame-time bars (all live). ``size`` is checked by hand (not in the list below):

    ``size`` = (256, 64): (width, height) of the graph in pixels, 1..4096 each (cut to the screen).
    """
    visible: bool = bool_field(False, "draw the bars (the times are recorded either way; F1 toggles them)")
    size: tuple = (256, 64)

    def __post_init__(self):
        super().__post_init__()
        o = "OverlaySettings"
        try:
            size = tuple(check_int(o, f"size[{i}]", n, 1, 4096) for i, n in enumerate(self.size))
        except TypeError:
            size = ()
        if len(size) != 2:
            raise ValueError(f"{o}.size must be (width, height) in pixels, got {self.size!r}")
        self.store(dict(size=size))


class FrameTimes:
    """Wall-clock milliseconds of the last HISTORY frames."""

    def __init__(self):
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


class OverlayPass(FullscreenPass):
    name = "overlay"
    phase = "overlay"
    fragment = "overlay/bars.frag"
    reads = (SCREEN,)                       # blends onto it
    writes = (SCREEN,)

    def __init__(self, plugin: "OverlayPlugin"):
        super().__init__(plugin)
        self.times = plugin.times
        self.data = None

    def setup(self, builder: PassBuilder) -> None:
        if self.plugin.settings.visible:    # hidden: declares nothing, culled until it is shown again
            super().setup(builder)

    def prepare(self, gpu) -> None:
        super().prepare(gpu)
        self.data = gpu.track(gpu.ctx.texture((HISTORY, 1), 1, dtype="f4"))
        self.data.filter = (gpu.ctx.NEAREST, gpu.ctx.NEAREST)

    def execute(self, frame: PassContext) -> None:
        settings = self.plugin.settings
        gpu = frame.gpu
        frame.resource(SCREEN).use()
        w, h = min(settings.size[0], gpu.size[0]), min(settings.size[1], gpu.size[1])
        self.data.write(np.asarray(self.times.ms, np.float32).tobytes())
        bind_textures(self.program, frame_ms=self.data)
        gpu.ctx.viewport = (4, 4, w, h) if gpu.size[0] > w + 8 else (0, 0, w, h)   # the graph resets it
        frame.blend_alpha()                  # over the screen; its alpha stays what present wrote (1)
        frame.fullscreen(self.program)

    def release(self) -> None:
        if self.data is not None:
            self.data.release()


class OverlayPlugin(Plugin):
    """The frame-time bars: ``OverlayPlugin(settings=None, **fields)`` with :class:`OverlaySettings`;
    ``configure(visible=...)`` shows or hides them on the next frame. Adds the FrameTimes resource."""

    settings_class = OverlaySettings

    def __init__(self, settings: OverlaySettings | None = None, **fields):
        super().__init__(settings, **fields)
        self.times = FrameTimes()

    def build(self, app) -> None:
        app.insert_resource(self.times)
        app.add_system(record_frame_time, "update", label="record_frame_time")
        app.add_system(self.toggle, "update", label="overlay_toggle")
        if app.graph is not None:
            app.graph.add_pass(OverlayPass(self))
            app.graph.want_timings(self, self.settings.visible)

    def toggle(self, app) -> None:
        """F1 pressed this frame (in the App's :class:`atmos.Input`, if it has one): show or hide;
        per-pass timings are wanted while shown."""
        inp = app.get_resource(Input)
        if inp is not None and key.F1 in inp.pressed:
            self.configure(visible=not self.settings.visible)
        if app.graph is not None:
            app.graph.want_timings(self, self.settings.visible)

    def cleanup(self, app) -> None:
        if app.graph is not None:
            app.graph.want_timings(self, False)
