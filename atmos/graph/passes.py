"""RenderPass, the base class of every pass, and PassBuilder, through which a pass declares its resources."""
from __future__ import annotations

from atmos.gpu.context import GpuContext
from atmos.graph.errors import GraphError
from atmos.graph.frame import PassContext
from atmos.graph.phases import PHASE_INDEX, PHASES
from atmos.gpu.hazards import ACCESS
from atmos.graph.resources import BufferDesc, TextureDesc


class RenderPass:
    """One step of a frame. Subclass it, set ``name`` and ``phase``, override what you need.

    ``phase`` is one of :data:`atmos.graph.PHASES`; inside a phase the order follows the data the
    passes declare. ``setup`` declares resources and runs every frame (keep it cheap: read settings,
    declare; the graph recompiles only when the declarations change). ``prepare`` is called once,
    lazily, for passes that survive culling, before their first ``execute`` — make buffers there,
    never in ``__init__`` or ``setup``; ``release`` frees what ``prepare`` made. ``before``/``after``
    name passes of the same phase this one must run before/after (rarely needed: prefer data).
    ``exclusive``: a group name for passes that are alternatives to each other (the two cloud
    renderers: "cloud volume"): at most one pass of a group may declare anything in a frame, else
    the compile raises a GraphError naming them (a pass that is switched off declares nothing).

    ``setup_key``: None (``setup`` runs every frame), or a method returning a tuple of what ``setup``
    reads (settings objects, which are replaced on a change, the frame size, whether an import exists,
    ...): while it equals (``==``) the key of the pass's last setup, the graph keeps those declarations
    and skips ``setup``. A setup that reads anything its key leaves out must not have one; a subclass
    that overrides ``setup`` gives its own key, else its setup runs every frame.
    """

    name: str = ""
    phase: str = ""
    before: tuple[str, ...] = ()
    after: tuple[str, ...] = ()
    exclusive: str = ""
    setup_key = None

    def setup(self, builder: PassBuilder) -> None:
        """Declare the resources this pass creates, reads and writes (every frame)."""

    def prepare(self, gpu: GpuContext) -> None:
        """Make GL objects (buffers, textures); called once before the first execute."""

    def execute(self, frame: PassContext) -> None:
        """Record this pass's GPU work; ``frame`` is the graph's PassContext (``frame.view``: camera, sun, clock)."""

    def release(self) -> None:
        """Free what ``prepare`` made; ``prepare`` runs again if the pass executes later."""

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} [{self.phase}]>"


class PluginPass(RenderPass):
    """A pass made by a plugin (``plugin``: its settings) around one program from the GPU context's
    program cache, compiled with :meth:`defines`: what FullscreenPass and ComputePass share."""

    def __init__(self, plugin=None):
        self.plugin = plugin
        self.gpu = None

    def defines(self) -> dict:
        """Compile-time constants of the pass's shader (``#define`` name value)."""
        return {}

    def prepare(self, gpu) -> None:
        self.gpu = gpu


def check_pass(p) -> None:
    """A GraphError unless ``p`` is a RenderPass with a name and a known phase."""
    if not isinstance(p, RenderPass):
        raise GraphError(f"add_pass needs a RenderPass, got {type(p).__name__}")
    if not isinstance(p.name, str) or not p.name:
        raise GraphError(f"pass of type {type(p).__name__} has no name; set RenderPass.name to a unique string")
    if p.phase not in PHASE_INDEX:
        raise GraphError(f"pass '{p.name}' ({type(p).__name__}) has phase {p.phase!r}; set RenderPass.phase "
                         f"to one of: {', '.join(PHASES)}")


class PassBuilder:
    """Collects one pass's declarations during ``setup``.

    ``read(name)`` reads the version of ``name`` current when the pass runs; ``read(name, at=phase)``
    names the version left at the end of an earlier phase (the compiler checks that nothing writes
    it in between). A pass that blends onto a resource reads and writes it.

    Each declaration says how (``access``, one of :data:`atmos.gpu.hazards.ACCESS`): reads default to
    ``sampled`` (``storage`` for buffers), writes to ``attachment`` (``storage`` for buffers); a compute
    pass writes ``storage``. Before a pass runs, the graph issues the memory barrier its declared uses
    need after earlier storage writes (:mod:`atmos.gpu.hazards`); a storage write of a created texture
    needs a ``TextureDesc(storage=True)``.
    """

    def __init__(self, pass_name: str):
        self.pass_name = pass_name
        self.creates: dict[str, TextureDesc | BufferDesc] = {}
        self.reads: dict[str, str | None] = {}      # name -> the phase whose version is read (None: current)
        self.writes: list[str] = []
        self.access: dict[str, tuple[str | None, str | None]] = {}   # name -> (read access, write access)
        self.has_side_effect = False

    def create(self, name: str, desc: TextureDesc | BufferDesc, access: str | None = None) -> None:
        """A transient texture or buffer this pass creates (its first writer, with ``access``); the pool provides it."""
        if type(name) is not str or not name:
            self._check(name)
        kind = type(desc)
        if kind is not TextureDesc and kind is not BufferDesc:
            if not isinstance(desc, (TextureDesc, BufferDesc)):
                raise GraphError(f"pass '{self.pass_name}' creates '{name}' with {desc!r}; a TextureDesc or "
                                 "BufferDesc is required")
            kind = BufferDesc if isinstance(desc, BufferDesc) else TextureDesc
        if name in self.creates:
            raise GraphError(f"pass '{self.pass_name}' creates '{name}' twice")
        if access is None:
            access = "storage" if kind is BufferDesc else "attachment"
        elif access not in ACCESS:
            self._access(name, access, None)         # the error
        if access == "storage" and kind is TextureDesc and not desc.storage:
            raise GraphError(f"pass '{self.pass_name}' creates '{name}' for storage writes, but its TextureDesc "
                             f"({desc}) has storage=False; give TextureDesc(..., storage=True)")
        if kind is BufferDesc and access not in ("storage", "copy"):
            raise GraphError(f"pass '{self.pass_name}' creates buffer '{name}' with access {access!r}; "
                             "a pass writes a buffer with 'storage' or 'copy'")
        self.creates[name] = desc
        held = self.access
        held[name] = (held[name][0] if name in held else None, access)

    def read(self, name: str, at: str | None = None, access: str | None = None) -> None:
        """This pass samples (or blends onto) ``name``; ``at``: the phase whose final version it needs;
        ``access``: how it reads it (default ``sampled``; ``storage`` for image loads and storage blocks)."""
        if type(name) is not str or not name:
            self._check(name)
        if at is not None and at not in PHASE_INDEX:
            raise GraphError(f"pass '{self.pass_name}' reads '{name}' at phase {at!r}; "
                             f"allowed: {', '.join(PHASES)}")
        self.reads[name] = at
        held = self.access
        if access is not None and access not in ACCESS:
            self._access(name, access, None)         # the error
        held[name] = (access, held[name][1] if name in held else None)

    def write(self, name: str, access: str | None = None) -> None:
        """This pass modifies an existing resource (read-modify-write passes also call ``read``);
        ``access``: how it writes it (default ``attachment``; ``storage`` for image stores)."""
        if type(name) is not str or not name:
            self._check(name)
        if name not in self.writes:
            self.writes.append(name)
        held = self.access
        if access is not None and access not in ACCESS:
            self._access(name, access, None)         # the error
        held[name] = (held[name][0] if name in held else None, access)

    def _access(self, name: str, access: str | None, default: str | None) -> str | None:
        if access is None:
            return default
        if access not in ACCESS:
            raise GraphError(f"pass '{self.pass_name}' declares '{name}' with access {access!r}; "
                             f"allowed: {', '.join(ACCESS)}")
        return access

    def side_effect(self) -> None:
        """Keep this pass even if nothing reads its outputs."""
        self.has_side_effect = True

    @property
    def names(self) -> frozenset[str]:
        """Every resource name this pass declared."""
        return frozenset(self.creates) | frozenset(self.reads) | frozenset(self.writes)

    def key(self) -> tuple:
        """The declarations as a comparable value: the graph recompiles when a pass's key changes."""
        return (tuple(self.creates.items()), tuple(self.reads.items()), tuple(self.writes),
                tuple(self.access.items()), self.has_side_effect)

    def uses(self, name: str) -> str:
        """How this pass uses ``name``: 'create', 'read', 'write', 'read/write' or ''."""
        if name in self.creates:
            return "create"
        return "/".join(kind for kind, names in (("read", self.reads), ("write", self.writes)) if name in names)

    def _check(self, name) -> None:
        if not isinstance(name, str) or not name:
            raise GraphError(f"pass '{self.pass_name}': resource names must be non-empty strings, got {name!r}")
