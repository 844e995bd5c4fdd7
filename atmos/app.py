"""The App: one ECS world, resources, a schedule of systems, a render graph and a frame scheduler."""
from __future__ import annotations

import time
import weakref

import numpy as np

from atmos.checks import check_int, check_num
from atmos.clock import FixedClock
from atmos.slicing import FrameScheduler
from atmos.gpu.context import require_gpu
from atmos.graph import RenderGraph
from atmos.plugin import Plugin, PluginGroup
from atmos.render_core import LinearCapturePass
from atmos.scene_view import SceneView
from atmos.schedule import Schedule
from atmos.states import InState, States
from atmos.timers import Timer, Timers
from atmos.world import World


_OWNERS: "weakref.WeakKeyDictionary[Plugin, weakref.ref]" = weakref.WeakKeyDictionary()   # each plugin's App (weakly)


class AppError(RuntimeError):
    """The App cannot do this now: it was closed, or its start-up failed; the message says which."""


class App:
    """A game or demo scene. Plugins fill it; :meth:`update` runs one frame.

    ``gpu`` is an :class:`atmos.gpu.GpuContext` (window or headless); without one the App runs its
    systems only (no render graph), which is what the framework-overhead benchmark and logic tests use.

    Game logic: :meth:`after` / :meth:`every` are timers in game time (:mod:`atmos.timers`: they fire at
    the start of the ``update`` stage); :meth:`add_state`, :meth:`set_state`, :meth:`on_enter`,
    :meth:`on_exit`, :attr:`state` and ``add_system(..., in_state=)`` are game states
    (:mod:`atmos.states`: a change takes effect at the next frame boundary).

    Lifetime: :meth:`close` releases everything (``gpu.release()`` closes the Apps on it first); after
    it every other method is an :class:`AppError`. A plugin whose ``build`` raises is taken out again
    with what it registered; a start-up that raised leaves the App unable to run (AppError).
    """

    def __init__(self, gpu=None, *, fixed_step: float = 1 / 30, max_frame_dt: float = 0.1):
        if gpu is not None:
            require_gpu(gpu, "App gpu")._require_live()
        self.gpu = gpu
        self.world = World()
        self.schedule = Schedule()
        self.clock = FixedClock(fixed_step, max_frame_dt)
        self.resources: dict[type, object] = {}
        self.plugins: list[Plugin] = []
        self.graph = RenderGraph(gpu) if gpu is not None else None
        self.frames = FrameScheduler()
        self.timers = Timers()
        self.states = States()
        self.running = True
        self._started = self._finished = self._closed = False
        self._finished_plugins: set[int] = set()     # id() of plugins whose finish ran
        self._closed_by = "App.close"
        self._startup_error: BaseException | None = None
        if gpu is not None:
            gpu._apps.add(self)
        self.add_system(lambda app: app.timers.run(app), "update", label="app.timers")   # first in update
        self.add_system(lambda app: app.frames.tick(), "render", label="frame_scheduler")
        if self.graph is not None:
            self.add_system(App.render, "render", label="render_graph", after="frame_scheduler")

    # -- building --------------------------------------------------------------------------
    def add_plugins(self, *plugins: Plugin | PluginGroup) -> "App":
        """Build plugins (and every plugin of a group) into this App, in order; one call is all or
        nothing: when a plugin is refused or its ``build`` raises, every plugin of the call is taken out
        again, with the systems, passes, imports, resources and jobs they added (and their ``cleanup``
        run), so a corrected call can follow. A plugin instance belongs to one open App at a time."""
        self._check_open("add_plugins")
        self._activate()
        mark = self._mark()
        try:
            for item in plugins:
                for plugin in (item if isinstance(item, PluginGroup) else [item]):
                    self._add_one(plugin)
        except BaseException as error:
            for plugin in self.plugins[mark[0]:]:
                _OWNERS.pop(plugin, None)
            self._undo(mark, error)
            raise
        return self

    def _add_one(self, plugin) -> None:
        if not isinstance(plugin, Plugin):
            raise TypeError(f"add_plugins takes Plugin or PluginGroup instances, not {type(plugin).__name__}")
        if any(type(p) is type(plugin) for p in self.plugins):
            raise ValueError(f"{plugin.name} was added twice; each plugin type may be added once")
        owner = _OWNERS.get(plugin, lambda: None)()
        if owner is not None and owner is not self and not owner._closed:
            raise ValueError(f"this {plugin.name} belongs to another App that is still open (it holds that App's "
                             f"GPU objects and systems); make a new {plugin.name}(...) for this App, or close "
                             f"the other first")
        self.plugins.append(plugin)
        _OWNERS[plugin] = weakref.ref(self)
        try:
            plugin.build(self)
        except AttributeError as error:
            if self.graph is None and "'NoneType' object has no attribute" in str(error):
                raise AppError(f"{plugin.name} draws with the GPU and this App has none: make it with a context, "
                               f"App(atmos.create_headless()) or App(gpu) of a window (App() alone runs systems "
                               f"only)") from error
            raise

    def _mark(self) -> tuple:
        """What :meth:`_undo` needs to take a failed build out again."""
        return (len(self.plugins), len(self.schedule.systems), dict(self.resources), list(self.frames.jobs),
                self.graph.mark() if self.graph is not None else None, self.timers.mark(), self.states.mark())

    def _undo(self, mark: tuple, error: BaseException) -> None:
        """Remove the plugins (a failed one, and what its build added) and registrations made since ``mark``."""
        plugins, systems, resources, jobs, graph, timers, states = mark
        for plugin in reversed(self.plugins[plugins:]):
            try:
                plugin.cleanup(self)
            except Exception as failure:   # a half-built plugin may not clean up; the build error matters
                error.add_note(f"{plugin.name}.cleanup after the failed build also failed: {failure!r}")
        del self.plugins[plugins:]
        self.schedule.truncate(systems)
        self.resources.clear()
        self.resources.update(resources)
        for job in [j for j in self.frames.jobs if not any(j is k for k in jobs)]:
            self.frames.remove(job)
        if self.graph is not None:
            self.graph.undo(graph)
        self.timers.undo(timers)
        self.states.undo(states)

    def add_system(self, func, stage: str = "update", label: str | None = None, before=(), after=(), *,
                   in_state: str | None = None) -> "App":
        """Run ``func(app)`` in ``stage`` every frame (``simulate``: every fixed step); ``in_state``:
        only while the App is in that state (one declared with :meth:`add_state`)."""
        self._check_open("add_system")
        if in_state is not None:
            self.states.check("App.add_system", in_state, "in_state")
        system = self.schedule.add(func, stage, label, before, after)
        if in_state is not None:
            system.func = InState(func, in_state)
        return self

    def insert_resource(self, resource) -> "App":
        """Store one object per type, reachable with ``app.resource(Type)``."""
        self._check_open("insert_resource")
        if resource is None or isinstance(resource, type):
            raise ValueError(f"insert_resource takes an object (one per type), got {resource!r}"
                             + (f"; did you mean {resource.__name__}()?" if isinstance(resource, type) else ""))
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

    def init_resource(self, kind: type):
        """The ``kind`` resource, made with ``kind()`` and inserted first if the App has none."""
        resource = self.resources.get(kind)
        if resource is None:
            resource = kind()
            self.insert_resource(resource)
        return resource

    # -- timers and states ----------------------------------------------------------------
    def after(self, seconds: float, fn, *, in_state: str | None = None) -> Timer:
        """Call ``fn(app)`` once, ``seconds`` (finite, > 0) of game time from now, at the start of a
        frame's ``update`` stage (:mod:`atmos.timers`). ``in_state``: the timer belongs to that state,
        the current one, and is cancelled when the App leaves it."""
        self._check_open("after")
        return self._timer("App.after", seconds, fn, 1, in_state)

    def every(self, seconds: float, fn, times: int | None = None, *, in_state: str | None = None) -> Timer:
        """Call ``fn(app)`` every ``seconds`` (finite, > 0) of game time, ``times`` times (a whole number
        >= 1; None: until cancelled); a long frame fires once per missed period (:mod:`atmos.timers`).
        ``in_state`` as in :meth:`after`."""
        self._check_open("every")
        return self._timer("App.every", seconds, fn, times, in_state)

    def _timer(self, owner: str, seconds, fn, times, in_state) -> Timer:
        if in_state is not None:
            self.states.check(owner, in_state, "in_state")
            if in_state != self.states.current:
                raise ValueError(f"{owner}.in_state {in_state!r} is not the current state "
                                 f"{self.states.current!r}; make a state's timers while in it, e.g. in "
                                 f"app.on_enter({in_state!r}, ...)")
        return self.timers.add(owner, seconds, fn, times, self.clock.frame_time, in_state)

    def add_state(self, *names: str, initial: str | None = None) -> "App":
        """Declare the game states, once (:mod:`atmos.states`); ``initial`` (default: the first) is
        entered after the ``startup`` stage."""
        self._check_open("add_state")
        self.states.declare("App.add_state", names, initial)
        return self

    def set_state(self, name: str) -> None:
        """Change to state ``name`` at the next frame boundary (the end of this frame, or the start of
        the next when asked between frames): on_exit hooks, the switch, on_enter hooks. The last
        request before the boundary wins; the current state again restarts it."""
        self._check_open("set_state")
        self.states.next = self.states.check("App.set_state", name, "name")

    def on_enter(self, state: str, fn) -> "App":
        """Run ``fn(app)`` each time the App enters ``state`` (the initial state: after start-up)."""
        self._check_open("on_enter")
        self.states.hook("App.on_enter", "enter", state, fn)
        return self

    def on_exit(self, state: str, fn) -> "App":
        """Run ``fn(app)`` each time the App leaves ``state`` (before its timers are cancelled)."""
        self._check_open("on_exit")
        self.states.hook("App.on_exit", "exit", state, fn)
        return self

    @property
    def state(self) -> str | None:
        """The current game state (None when none were declared); a change shows after its boundary."""
        return self.states.current

    def _apply_states(self) -> None:
        """A frame boundary: the state changes asked for (then deleted entities are gone)."""
        if self.states.apply(self):
            self.world.clear_dead_entities()

    # -- running ---------------------------------------------------------------------------
    def finish(self) -> None:
        """Finish building: plugins' ``finish``, the schedule checked (unknown labels and cycles fail
        here), the render graph compiled. Runs no system: what ``atmos graph`` needs."""
        if self._finished:
            return
        self._check_open("finish")
        self._activate()
        for plugin in self.plugins:
            if id(plugin) not in self._finished_plugins:   # a retry after a failure runs each finish once
                plugin.finish(self)
                self._finished_plugins.add(id(plugin))
        self.schedule.build()
        if self.graph is not None:
            self.graph.compile()
        self._finished = True

    def startup(self) -> None:
        """:meth:`finish`, then run the ``startup`` stage once (simulations warm up there). If a
        start-up system raises, the App cannot run: this and every later frame raise AppError."""
        self._check_open("startup")
        if self._startup_error is not None:
            raise AppError(f"this App's start-up failed ({type(self._startup_error).__name__}: "
                           f"{self._startup_error}); close it and build a new App") from self._startup_error
        if self._started:
            return
        self.finish()
        self._started = True
        try:
            self.schedule.run("startup", self)
            self._apply_states()                          # the initial state's on_enter hooks
        except BaseException as error:
            self._startup_error = error
            raise

    def update(self, frame_dt: float | None = None) -> None:
        """Run one frame: update (due timers first), the due fixed ``simulate`` steps, render, last;
        state changes asked for take effect at its ends (:meth:`set_state`). ``frame_dt``:
        seconds since the last frame (a finite number >= 0; the clock clamps it to ``max_frame_dt``),
        or None to measure it."""
        self._check_open("update")
        if frame_dt is not None:
            frame_dt = check_num("App.update", "frame_dt", frame_dt, 0.0, optional=True)
        if not self._started or self._startup_error is not None:
            self.startup()
        if frame_dt is None:
            now = time.perf_counter()
            frame_dt = now - getattr(self, "_last", now)
            self._last = now
        self._activate()
        self._apply_states()                              # a set_state asked for between frames
        steps = self.clock.advance(frame_dt)
        self._run("update")
        for _ in range(steps):
            self._run("simulate")
            self.clock.tick()
        self._run("render")
        self._run("last")
        self._apply_states()

    def _run(self, stage: str) -> None:
        """One stage, then the ECS world's deferred deletes: an entity deleted in a stage is gone
        from every later stage's queries (and from the frame drawn after it)."""
        self.schedule.run(stage, self)
        self.world.clear_dead_entities()

    def render(self) -> None:
        """Run the render graph once with the scene as it is (what the render stage does each frame;
        tests and tools call it to draw again without advancing time)."""
        self._require_graph("render").execute(SceneView.of(self))

    def read_linear(self):
        """Render once (like :meth:`render`) and return the linear HDR ``color`` before exposure and
        tone mapping: float32 (height, width, 4), first row at the top (alpha: sky occlusion)."""
        graph = self._require_graph("read_linear")
        capture = next((p for p in graph.passes if isinstance(p, LinearCapturePass)), None)
        if capture is None:                  # kept once added: reads back only when armed
            capture = graph.add_pass(LinearCapturePass())
        capture.armed = True
        try:
            graph.execute(SceneView.of(self))
        finally:
            capture.armed = False
        return np.ascontiguousarray(capture.color[::-1], dtype=np.float32)

    def run_frames(self, n: int, dt: float = 1 / 60) -> None:
        """:meth:`update` ``n`` times (a whole number >= 0) with frame time ``dt`` (finite, >= 0)."""
        n = check_int("App.run_frames", "n", n, 0, 2**62)
        dt = check_num("App.run_frames", "dt", dt, 0.0)
        for _ in range(n):
            self.update(dt)

    @property
    def closed(self) -> bool:
        """True once :meth:`close` ran."""
        return self._closed

    def _check_open(self, what: str) -> None:
        if self._closed:
            raise AppError(f"App.{what}: this App was closed ({self._closed_by}); build a new App")

    def _require_graph(self, what: str):
        """The render graph, for ``App.<what>``: an AppError when closed or made without a GPU context."""
        self._check_open(what)
        if self.graph is None:
            raise AppError(f"App.{what}: this App has no GPU context (App(gpu)), so nothing to render")
        return self.graph

    def _activate(self) -> None:
        """Make this App's ECS world and GL context the current ones."""
        self.world.activate()
        if self.gpu is not None:
            self.gpu.make_current()

    def close(self) -> None:
        """Release every plugin's GL objects, the render graph and the ECS world: all of them even when
        some fail; then one AppError lists the failures. Closing again does nothing."""
        if self._closed:
            return
        self._closed = True
        failures = []

        def attempt(what, func, *args):
            try:
                func(*args)
            except Exception as error:
                failures.append((what, error))

        attempt("making its context current", self._activate)
        for plugin in reversed(self.plugins):
            attempt(f"{plugin.name}.cleanup", plugin.cleanup, self)
        if self.graph is not None:
            attempt("the render graph's release", self.graph.release)
        attempt("the frame scheduler's release", self.frames.release)
        attempt("the ECS world's close", self.world.close)
        if self.gpu is not None:
            self.gpu._apps.discard(self)
        if failures:
            listed = "; ".join(f"{what}: {type(error).__name__}: {error}" for what, error in failures)
            raise AppError(f"App.close released everything else, but {len(failures)} step(s) failed: "
                           f"{listed}") from failures[0][1]
