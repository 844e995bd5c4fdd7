"""RenderGraph: register passes and imported resources; every frame, declare, (re)compile if the
declarations changed, execute."""
from __future__ import annotations

from typing import Any, Callable

from atmos.frame_constants import frame_constants, view_frame
from atmos.gpu.hazards import barrier_bit
from atmos.gpu.host_memory import trim_heap
from atmos.graph.compiler import CompiledGraph, compile_graph
from atmos.graph.dump import dump_text, dump_dot
from atmos.graph.errors import GraphError
from atmos.graph.frame import PassContext
from atmos.graph.passes import PassBuilder, RenderPass, check_pass
from atmos.graph.resources import TexturePool
from atmos.graph.timing import PassTimers


class RenderGraph:
    """A Frostbite-style frame graph.

    Passes declare resources and a phase in ``setup``, which runs every frame unless the pass's
    ``setup_key`` says nothing it reads changed (:class:`RenderPass`); :meth:`compile`
    recompiles only when the declarations (or the set of passes and imports) changed: it orders the
    passes by phase and data, versions every write, culls those whose outputs nothing needs
    (writing an imported resource is a side effect) and plans when each transient texture is taken
    from and given back to :attr:`pool`, so textures alias across the frame.

    Per-pass timings (:attr:`timings`) are off by default: a frame then makes no timer query. Turn
    them on with ``graph.timings_enabled = True`` (a benchmark, a tool), or let whatever shows them
    ask with ``graph.want_timings(owner)`` and ``graph.want_timings(owner, False)`` (the overlay does
    while it is visible); they run while either is on.
    """

    def __init__(self, gpu):
        self.gpu = gpu
        self.pool = TexturePool(gpu)
        self._timings_on = False
        self._timings_wanted: set = set()
        self.compiles = 0                       # how often the declarations changed (tests, benchmarks)
        self._passes: dict[str, RenderPass] = {}
        self._imports: dict[str, object] = {}
        self._compiled: CompiledGraph | None = None
        self._key: tuple | None = None
        self._declared = None                # the last declarations (passes, their phases, builders, imports)
        self._setups: dict[str, tuple] = {}  # pass name -> (pass, its setup_key, its builder): setups kept
        self._keys: dict[str, Callable | None] = {}   # pass name -> its setup_key where that covers its setup
        self._prepared: dict[str, RenderPass] = {}
        self._timers = PassTimers(gpu.ctx)
        self._frame = PassContext(gpu)

    # -- building ---------------------------------------------------------------------------
    @property
    def passes(self) -> tuple[RenderPass, ...]:
        """Every registered pass (in no meaningful order: the compiled order is by phase and data)."""
        return tuple(self._passes.values())

    def add_pass(self, p: RenderPass) -> RenderPass:
        """Register ``p``; its name must be unique in this graph and its phase one of PHASES."""
        check_pass(p)
        if p.name in self._passes:
            raise GraphError(f"the graph already has a pass named '{p.name}' "
                             f"({type(self._passes[p.name]).__name__}); pass names must be unique")
        self._passes[p.name] = p
        self._keys[p.name] = setup_key_of(p)
        return p

    def shared_pass(self, kind: type, make: Callable[[], RenderPass]) -> tuple[RenderPass, bool]:
        """(the graph's pass of type ``kind``, whether it was made now): a pass several plugins need (a bake
        they all read) is added by the first of them with ``make()``, then found by the rest."""
        for p in self._passes.values():
            if isinstance(p, kind):
                return p, False
        return self.add_pass(make()), True

    def remove_pass(self, name: str) -> None:
        """Unregister pass ``name`` and release what its ``prepare`` made."""
        p = self._passes.pop(name, None)
        if p is None:
            raise GraphError(f"the graph has no pass '{name}' (passes: {', '.join(self._passes) or 'none'})")
        if self._prepared.get(name) is p:
            del self._prepared[name]
            p.release()
        self._setups.pop(name, None)
        del self._keys[name]
        self._timers.forget(name)

    def import_resource(self, name: str, source: Any | Callable[[], Any]) -> None:
        """A persistent resource made outside the graph: a moderngl texture or framebuffer, any other
        object passes read (the cloud simulation's texture sets), or a zero-argument callable returning
        the current one (resolved once per frame). Replacing the source of a known name does not recompile."""
        if not isinstance(name, str) or not name:
            raise GraphError(f"imported resource names must be non-empty strings, got {name!r}")
        if source is None:
            raise GraphError(f"import_resource('{name}', None): give a texture, a framebuffer, an object or "
                             "a callable returning one")
        self._imports[name] = source

    def imports(self, name: str) -> bool:
        """Whether the graph imports a resource called ``name`` (a pass may read an optional one)."""
        return name in self._imports

    def remove_import(self, name: str) -> None:
        """Forget the imported resource ``name`` (a plugin that made it is going away)."""
        if self._imports.pop(name, None) is None:
            raise GraphError(f"the graph imports no resource '{name}' (imports: {', '.join(self._imports) or 'none'})")

    def mark(self) -> tuple:
        """The registered passes and imports now, for :meth:`undo`."""
        return set(self._passes), dict(self._imports)

    def undo(self, mark: tuple) -> None:
        """Go back to ``mark``: remove the passes added since, restore the imports (a failed plugin build)."""
        passes, imports = mark
        for name in set(self._passes) - passes:
            self.remove_pass(name)
        self._imports.clear()
        self._imports.update(imports)

    # -- compiling and running ---------------------------------------------------------------
    def declare(self) -> dict[str, PassBuilder]:
        """This frame's declarations: every pass's ``setup`` runs, but for a pass whose ``setup_key()``
        equals the one of its last setup, whose builder is kept (:class:`RenderPass`)."""
        builders, kept, keys = {}, self._setups, self._keys
        for p in self._passes.values():
            name = p.name
            key_of = keys[name]
            if key_of is not None:
                key = key_of()
                if name in kept:
                    held = kept[name]
                    if held[0] is p and held[1] == key:
                        builders[name] = held[2]
                        continue
            builder = builders[name] = PassBuilder(name)
            p.setup(builder)
            if key_of is not None:
                kept[name] = (p, key, builder)
        return builders

    def compile(self) -> CompiledGraph:
        """This frame's compiled graph: the passes declare (:meth:`declare`); the graph is compiled
        again only when a declaration, a phase, a pass or an import changed."""
        builders = self.declare()
        passes = list(self._passes.values())
        if not self._same_declarations(passes, builders):
            key = (tuple((p.name, p.phase, p.before, p.after, builders[p.name].key()) for p in passes),
                   tuple(self._imports))
        else:
            key = self._key
        self._declared = (passes, [(p.name, p.phase, p.before, p.after) for p in passes], builders, tuple(self._imports))
        if key != self._key:
            compiled = compile_graph(list(self._passes.values()), builders, self._imports)
            self._compiled, self._key = compiled, key
            self.compiles += 1
            self._timers.keep_only(set(compiled.kept))
        return self._compiled

    def _same_declarations(self, passes, builders) -> bool:
        """Whether the passes, their phases and orderings, their declarations (in order) and the imports
        are those of the last compile: the cheap check that spares building the graph's key."""
        last = self._declared
        if last is None or last[0] != passes or last[3] != tuple(self._imports):
            return False
        old = last[2]
        for p, meta in zip(passes, last[1]):
            if (p.name, p.phase, p.before, p.after) != meta:
                return False
            b, o = builders[p.name], old[p.name]
            if b is o:                           # a kept setup's builder
                continue
            if (b.has_side_effect != o.has_side_effect or b.writes != o.writes      # values, then key order
                    or b.reads != o.reads or b.access != o.access or b.creates != o.creates
                    or list(b.reads) != list(o.reads) or list(b.access) != list(o.access)
                    or list(b.creates) != list(o.creates)):
                return False
        return True

    def execute(self, view=None) -> None:
        """Run one frame: kept passes in order; ``view`` (an :class:`atmos.SceneView`: camera, sun,
        clock, size) is what passes see as ``frame.view``, and what the frame block
        (``lib/frame.glsl``, :mod:`atmos.frame_constants`) holds while the frame runs: written and
        bound here, once."""
        compiled = self.compile()
        plan = compiled.plan
        if plan is None:
            plan = compiled.plan = _plan(compiled)
        resources: dict[str, object] = {}
        ids: dict[str, int] = {}                 # id() of each resource this frame, for the hazard checks
        for name in compiled.imports_used:
            resources[name] = obj = self._resolve(name)
            ids[name] = id(obj)
        transient: dict[str, object] = {}
        frame = self._frame
        timed = self.timings_enabled
        if not timed and self._timers.held:
            self._timers.stop()                  # timing turned off: its queries go back to the pool
        frame.view, frame._resources = view, resources
        hazards = self.gpu.hazards
        pool, prepared = self.pool, self._prepared
        data = view_frame(view) if view is not None else None
        block = frame_constants(self.gpu) if data is not None else None
        if block is not None:
            block.begin(data)
        try:
            for p, name, acquire, uses, stored, declared, access, release in plan:
                for r, desc in acquire:
                    resources[r] = transient[r] = texture = pool.acquire(desc)
                    ids[r] = id(texture)
                if name not in prepared or prepared[name] is not p:
                    p.prepare(self.gpu)
                    prepared[name] = p
                dirty = hazards._dirty      # the barrier this pass's declared uses need, before it
                if dirty:
                    _barrier_before(hazards, dirty, resources, ids, uses)
                frame.pass_name, frame._declared, frame._access = name, declared, access
                frame.reset_state()
                if timed:
                    self._timers.begin(name)
                    try:
                        p.execute(frame)
                    finally:
                        self._timers.end(name)
                else:
                    p.execute(frame)
                if stored:
                    hazards.wrote_storage(map(resources.__getitem__, stored))
                for r in release:
                    texture = transient[r]
                    del resources[r], transient[r]
                    pool.release(texture)
        finally:
            for texture in transient.values():  # only after an exception
                pool.release(texture)
            if timed:
                self._timers.end_frame()
            frame._end_frame()
            if block is not None:
                block.end()                # inside another graph's pass: that frame's block again
            if pool.end_frame():  # evicted textures: drop the cached framebuffers over them
                frame.drop_released()
                if self.gpu.software:  # their storage was host memory: give the heap's free pages back
                    trim_heap()

    def _resolve(self, name: str):
        source = self._imports[name]
        resource = source() if callable(source) else source
        if resource is None:
            raise GraphError(f"imported resource '{name}': its callable returned None this frame")
        return resource

    @property
    def timings(self) -> dict[str, tuple[float, float]]:
        """Pass name -> (gpu_ms, cpu_ms) of the latest measurement whose GPU result came in (kept
        passes only; a frame or two behind; empty until timings are on, see :attr:`timings_enabled`)."""
        return self._timers.results

    @property
    def timings_enabled(self) -> bool:
        """Whether frames time their passes: set True or False by hand, or on while anyone
        :meth:`want_timings`."""
        return self._timings_on or bool(self._timings_wanted)

    @timings_enabled.setter
    def timings_enabled(self, on: bool) -> None:
        self._timings_on = bool(on)

    def want_timings(self, owner, wanted: bool = True) -> None:
        """``owner`` (any hashable, e.g. a plugin) shows or records timings (``wanted``) or no longer does."""
        if wanted:
            self._timings_wanted.add(owner)
        else:
            self._timings_wanted.discard(owner)

    # -- inspection and cleanup ----------------------------------------------------------------
    def dump(self) -> str:
        """The compiled graph as text: phases, execution order with versions, culled passes and why, resources."""
        return dump_text(self.compile())

    def to_dot(self) -> str:
        """The compiled graph in Graphviz dot."""
        return dump_dot(self.compile())

    def picture(self, title: str = ""):
        """The compiled graph drawn as a PIL image (:mod:`atmos.graph.picture`)."""
        from atmos.graph.picture import draw_frame      # Pillow only when a picture is asked for
        return draw_frame(self.compile(), title)

    def release(self) -> None:
        """Release passes' GL objects, the pool's textures, cached framebuffers and timer queries.

        The graph stays usable: the next execute prepares passes again.
        """
        for p in self._prepared.values():
            p.release()
        self._prepared.clear()
        self._frame.release()
        self.pool.release_all()
        self._timers.release()


def setup_key_of(p: RenderPass) -> Callable | None:
    """``p.setup_key`` where it covers ``p.setup``: None when there is none, or when a subclass overrides
    ``setup`` below the class that gave the key (whose key would leave out what that setup reads)."""
    mro = type(p).__mro__
    key_owner = next(c for c in mro if "setup_key" in c.__dict__)
    setup_owner = next(c for c in mro if "setup" in c.__dict__)
    return p.setup_key if issubclass(key_owner, setup_owner) else None


def _plan(compiled: CompiledGraph) -> list[tuple]:
    """Per kept pass, what :meth:`RenderGraph.execute` does around it, worked out once per compile:
    (pass, name, [(transient, desc) to acquire], uses, names it writes as storage, declared names,
    access by name, transients to release). ``uses`` are (name, bit for a texture, bit for a buffer):
    the barrier bit each declared use needs after a storage write (an undeclared access is the
    kind's default: textures ``sampled`` when read, ``attachment`` when written; buffers ``storage``)."""
    plan = []
    for i, p in enumerate(compiled.order):
        reads, writes, stored = compiled.uses[i]
        uses = tuple((n, barrier_bit("texture", a or default), barrier_bit("buffer", a or "storage"))
                     for group, default in ((reads, "sampled"), (writes, "attachment")) for n, a in group)
        plan.append((p, p.name, [(r, compiled.resources[r].desc) for r in compiled.acquire[i]], uses, stored,
                     compiled.declared[i], compiled.declarations[p.name].access or {}, compiled.release[i]))
    return plan


def _barrier_before(hazards, dirty: dict, resources: dict, ids: dict, uses: tuple) -> None:
    """The barrier a pass's declared ``uses`` (see :func:`_plan`) need before it, with what binds
    asked for: issued where any of its resources has a pending storage write."""
    need, hit = 0, False
    for name, texture_bit, buffer_bit in uses:
        key = ids[name]
        if key in dirty:
            hit = True
            entry = dirty[key]
            if entry[0]() is resources[name]:
                need |= entry[2] & (buffer_bit if entry[1] == "buffer" else texture_bit)
    if hit and (need or hazards._need):
        hazards.issue(need | hazards._need)
