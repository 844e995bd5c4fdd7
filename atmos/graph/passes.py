"""RenderPass, the base class of every pass, and PassBuilder, through which a pass declares its resources."""
from __future__ import annotations

from atmos.graph.errors import GraphError
from atmos.graph.resources import TextureDesc


class RenderPass:
    """One step of a frame. Subclass it and override what you need.

    ``setup`` declares resources (called by ``RenderGraph.compile``); ``prepare`` is called once,
    lazily, for passes that survive culling, before their first ``execute`` — compile shaders and
    make buffers there, never in ``__init__`` or ``setup``; ``release`` frees what ``prepare`` made.
    ``before``/``after`` name passes this one must run before/after.
    """

    name: str = ""
    before: tuple[str, ...] = ()
    after: tuple[str, ...] = ()

    def setup(self, builder: "PassBuilder") -> None:
        """Declare the resources this pass creates, reads and writes."""

    def prepare(self, gpu) -> None:
        """Make GL objects (programs, buffers); called once before the first execute."""

    def execute(self, frame) -> None:
        """Record this pass's GPU work; ``frame`` is the graph's PassContext."""

    def release(self) -> None:
        """Free what ``prepare`` made; ``prepare`` runs again if the pass executes later."""

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r}>"


class PassBuilder:
    """Collects one pass's declarations during ``setup``."""

    def __init__(self, pass_name: str):
        self.pass_name = pass_name
        self.creates: dict[str, TextureDesc] = {}
        self.reads: list[str] = []
        self.writes: list[str] = []
        self.has_side_effect = False

    def create(self, name: str, desc: TextureDesc) -> None:
        """A transient texture this pass creates (its first writer); the pool provides it."""
        self._check(name)
        if not isinstance(desc, TextureDesc):
            raise GraphError(f"pass '{self.pass_name}' creates '{name}' with {desc!r}; a TextureDesc is required")
        if name in self.creates:
            raise GraphError(f"pass '{self.pass_name}' creates '{name}' twice")
        self.creates[name] = desc

    def read(self, name: str) -> None:
        """This pass samples ``name``."""
        self._check(name)
        if name not in self.reads:
            self.reads.append(name)

    def write(self, name: str) -> None:
        """This pass modifies an existing resource (read-modify-write passes also call ``read``)."""
        self._check(name)
        if name not in self.writes:
            self.writes.append(name)

    def side_effect(self) -> None:
        """Keep this pass even if nothing reads its outputs."""
        self.has_side_effect = True

    @property
    def names(self) -> frozenset[str]:
        """Every resource name this pass declared."""
        return frozenset(self.creates) | frozenset(self.reads) | frozenset(self.writes)

    def uses(self, name: str) -> str:
        """How this pass uses ``name``: 'create', 'read', 'write', 'read/write' or ''."""
        if name in self.creates:
            return "create"
        return "/".join(kind for kind, names in (("read", self.reads), ("write", self.writes)) if name in names)

    def _check(self, name) -> None:
        if not isinstance(name, str) or not name:
            raise GraphError(f"pass '{self.pass_name}': resource names must be non-empty strings, got {name!r}")
