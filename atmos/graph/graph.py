"""RenderGraph: register passes and imported resources, compile once, execute every frame."""
from __future__ import annotations

from atmos.graph.compiler import CompiledGraph, compile_graph
from atmos.graph.dump import dump_text, dump_dot
from atmos.graph.errors import GraphError
from atmos.graph.frame import PassContext
from atmos.graph.passes import RenderPass
from atmos.graph.resources import TexturePool
from atmos.graph.timing import PassTimers


class RenderGraph:
    """A Frostbite-style frame graph.

    Passes declare resources in ``setup``; :meth:`compile` orders them, culls those whose outputs
    nothing needs (writing an imported resource is a side effect) and plans when each transient
    texture is taken from and given back to :attr:`pool`, so textures alias across the frame.
    """

    def __init__(self, gpu):
        self.gpu = gpu
        self.pool = TexturePool(gpu)
        self.timings_enabled = True
        self._passes: dict[str, RenderPass] = {}
        self._imports: dict[str, object] = {}
        self._compiled: CompiledGraph | None = None
        self._compiled_size = None
        self._prepared: dict[str, RenderPass] = {}
        self._timers = PassTimers(gpu.ctx)
        self._frame = PassContext(gpu)

    # -- building ---------------------------------------------------------------------------
    @property
    def passes(self) -> tuple[RenderPass, ...]:
        """Every registered pass, in registration order."""
        return tuple(self._passes.values())

    def add_pass(self, p: RenderPass) -> RenderPass:
        """Register ``p``; its name must be unique in this graph."""
        if not isinstance(p, RenderPass):
            raise GraphError(f"add_pass needs a RenderPass, got {type(p).__name__}")
        if not isinstance(p.name, str) or not p.name:
            raise GraphError(f"pass of type {type(p).__name__} has no name; set RenderPass.name to a unique string")
        if p.name in self._passes:
            raise GraphError(f"the graph already has a pass named '{p.name}' "
                             f"({type(self._passes[p.name]).__name__}); pass names must be unique")
        self._passes[p.name] = p
        self.invalidate()
        return p

    def remove_pass(self, name: str) -> None:
        """Unregister pass ``name`` and release what its ``prepare`` made."""
        p = self._passes.pop(name, None)
        if p is None:
            raise GraphError(f"the graph has no pass '{name}' (passes: {', '.join(self._passes) or 'none'})")
        if self._prepared.get(name) is p:
            del self._prepared[name]
            p.release()
        self._timers.forget(name)
        self.invalidate()

    def import_texture(self, name: str, source) -> None:
        """A persistent resource: a moderngl texture/framebuffer, or a zero-argument callable returning
        the current one (resolved once per frame). Replacing the source of a known name does not recompile."""
        if not isinstance(name, str) or not name:
            raise GraphError(f"imported resource names must be non-empty strings, got {name!r}")
        if source is None:
            raise GraphError(f"import_texture('{name}', None): give a texture, a framebuffer or a callable")
        if name not in self._imports:
            self.invalidate()
        self._imports[name] = source

    def invalidate(self) -> None:
        """Force the next :meth:`compile` to call every pass's ``setup`` again (after a pass changed
        what it declares)."""
        self._compiled = None

    # -- compiling and running ---------------------------------------------------------------
    def compile(self) -> CompiledGraph:
        """Order, validate and cull; cached until passes, imports or ``gpu.size`` change
        (descs often depend on the frame size), or :meth:`invalidate` is called."""
        if self._compiled is None or self._compiled_size != self.gpu.size:
            self._compiled = compile_graph(list(self._passes.values()), self._imports)
            self._compiled_size = self.gpu.size
            self._timers.keep_only(set(self._compiled.kept))
        return self._compiled

    def execute(self, **data) -> None:
        """Run one frame: kept passes in order; ``data`` is available as ``PassContext.data``."""
        compiled = self.compile()
        textures: dict[str, object] = {}
        for name in compiled.imports_used:
            textures[name] = self._resolve(name)
        transient: dict[str, object] = {}
        frame = self._frame
        frame._begin_frame(data, textures)
        try:
            for i, p in enumerate(compiled.order):
                for r in compiled.acquire[i]:
                    textures[r] = transient[r] = self.pool.acquire(compiled.resources[r].desc)
                if self._prepared.get(p.name) is not p:
                    p.prepare(self.gpu)
                    self._prepared[p.name] = p
                frame._begin_pass(p.name, compiled.declared[i])
                if self.timings_enabled:
                    with self._timers.measure(p.name):
                        p.execute(frame)
                else:
                    p.execute(frame)
                for r in compiled.release[i]:
                    del textures[r]
                    self.pool.release(transient.pop(r))
        finally:
            for texture in transient.values():  # only after an exception
                self.pool.release(texture)
            frame._end_frame()

    def _resolve(self, name: str):
        source = self._imports[name]
        resource = source() if callable(source) else source
        if resource is None:
            raise GraphError(f"imported resource '{name}': its callable returned None this frame")
        return resource

    @property
    def timings(self) -> dict[str, tuple[float, float]]:
        """Pass name -> (gpu_ms, cpu_ms) of the latest read-back measurement (kept passes only)."""
        return self._timers.results

    # -- inspection and cleanup ----------------------------------------------------------------
    def dump(self) -> str:
        """The compiled graph as text: execution order, culled passes and why, resources."""
        return dump_text(self.compile())

    def to_dot(self) -> str:
        """The compiled graph in Graphviz dot."""
        return dump_dot(self.compile())

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
