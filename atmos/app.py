"""The App: one ECS world, resources, a schedule of systems, a render graph and a frame scheduler."""
from __future__ import annotations

import time

from atmos.clock import FixedClock
from atmos.plugin import Plugin, PluginGroup
from atmos.scene_view import SceneView
from atmos.schedule import Schedule
from atmos.world import World


class App:
    """A game or demo scene. Plugins fill it; :meth:`update` runs one frame.

    ``gpu`` is an :class:`atmos.gpu.GpuContext` (window or headless); without one the App runs its
    systems only (no render graph), which is what the framework-overhead benchmark and logic tests use.
    """

    def __init__(self, gpu=None, *, fixed_step: float = 1 / 30, max_frame_dt: float = 0.1):
        from atmos.frames import FrameScheduler
        from atmos.graph import RenderGraph

        self.gpu = gpu
        self.world = World()
        self.schedule = Schedule()
        self.clock = FixedClock(fixed_step, max_frame_dt)
        self.resources: dict[type, object] = {}
        self.plugins: list[Plugin] = []
        self.graph = RenderGraph(gpu) if gpu is not None else None
        self.frames = FrameScheduler()
        self.running = True
        self._started = self._finished = False
        self.add_system(lambda app: app.frames.tick(), "render", label="frame_scheduler")
        if self.graph is not None:
            self.add_system(App.render, "render", label="render_graph", after="frame_scheduler")

    # -- building --------------------------------------------------------------------------
    def add_plugins(self, *plugins: Plugin | PluginGroup) -> "App":
        """Build plugins (and every plugin of a group) into this App, in order."""
        self._activate()
        for item in plugins:
            for plugin in (item if isinstance(item, PluginGroup) else [item]):
                if not isinstance(plugin, Plugin):
                    raise TypeError(f"add_plugins takes Plugin or PluginGroup instances, not {type(plugin).__name__}")
                if any(type(p) is type(plugin) for p in self.plugins):
                    raise ValueError(f"{plugin.name} was added twice; each plugin type may be added once")
                self.plugins.append(plugin)
                plugin.build(self)
        return self

    def add_system(self, func, stage: str = "update", label: str | None = None, before=(), after=()) -> "App":
        """Run ``func(app)`` in ``stage`` every frame (``simulate``: every fixed step)."""
        self.schedule.add(func, stage, label, before, after)
        return self

    def insert_resource(self, resource) -> "App":
        """Store one object per type, reachable with ``app.resource(Type)``."""
        self.resources[type(resource)] = resource
        return self

    def resource(self, kind: type):
        try:
            return self.resources[kind]
        except KeyError:
            have = ", ".join(sorted(t.__name__ for t in self.resources)) or "none"
            raise KeyError(f"no {kind.__name__} resource in this App (have: {have}); "
                           f"is the plugin that provides it added?") from None

    def get_resource(self, kind: type, default=None):
        return self.resources.get(kind, default)

    # -- running ---------------------------------------------------------------------------
    def finish(self) -> None:
        """Finish building: plugins' ``finish``, the schedule checked (unknown labels and cycles fail
        here), the render graph compiled. Runs no system: what ``atmos graph`` needs."""
        if self._finished:
            return
        self._activate()
        for plugin in self.plugins:
            plugin.finish(self)
        self.schedule.build()
        if self.graph is not None:
            self.graph.compile()
        self._finished = True

    def startup(self) -> None:
        """:meth:`finish`, then run the ``startup`` stage once (simulations warm up there)."""
        if self._started:
            return
        self.finish()
        self._started = True
        self.schedule.run("startup", self)

    def update(self, frame_dt: float | None = None) -> None:
        """Run one frame: update, the due fixed ``simulate`` steps, render, last."""
        if not self._started:
            self.startup()
        if frame_dt is None:
            now = time.perf_counter()
            frame_dt = now - getattr(self, "_last", now)
            self._last = now
        self._activate()
        steps = self.clock.advance(frame_dt)
        self.schedule.run("update", self)
        for _ in range(steps):
            self.schedule.run("simulate", self)
            self.clock.tick()
        self.schedule.run("render", self)
        self.schedule.run("last", self)

    def render(self) -> None:
        """Run the render graph once with the scene as it is (what the render stage does each frame;
        tests and tools call it to draw again without advancing time)."""
        self.graph.execute(SceneView.of(self))

    def run_frames(self, n: int, dt: float = 1 / 60) -> None:
        for _ in range(n):
            self.update(dt)

    def _activate(self) -> None:
        """Make this App's ECS world and GL context the current ones."""
        self.world.activate()
        if self.gpu is not None:
            self.gpu.make_current()

    def close(self) -> None:
        """Release every plugin's GL objects, the render graph and the ECS world."""
        self._activate()
        for plugin in reversed(self.plugins):
            plugin.cleanup(self)
        if self.graph is not None:
            self.graph.release()
        self.world.close()
