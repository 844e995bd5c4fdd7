"""Memory barriers from declared access, never by hand.

OpenGL makes a shader's image stores and storage-buffer writes ("storage" writes) visible to later
commands only after ``glMemoryBarrier`` with the bit of the way they are read next. :class:`Hazards`
remembers which GL objects (textures, buffers) were written that way and, when work that declared
how it uses them is about to run, issues one barrier with exactly the bits those uses need — once
per write and kind of use. Draws into attachments, uploads and copies are ordered by GL itself.

Uses are declared where they are made: :mod:`atmos.gpu.uniforms` binds samplers (``sampled``), images
and storage blocks (``storage``, writes taken from the GLSL's ``readonly``/``writeonly``) by name, and
each bind asks here for the barrier its use needs; :func:`dispatch` runs a compute program and marks
what it was bound to write as written; reads and uploads through moderngl (``texture.read``,
``buffer.write``...) and framebuffers the graph makes declare ``copy`` and ``attachment`` uses. No
code issues ``glMemoryBarrier`` itself.

Access kinds (also what :class:`atmos.graph.PassBuilder` declares):

==============  =======================================================================
``sampled``     read through a sampler (``texture``, ``texelFetch``)
``storage``     image load/store, a storage buffer (read, write or atomics)
``attachment``  a framebuffer attachment (drawn into, blended onto, depth-tested)
``copy``        read or written by a copy or an upload/readback (``texture.read``, ``buffer.write``)
``indirect``    a buffer of indirect draw/dispatch arguments
``uniform``     a buffer bound as a uniform block
``vertex``      a vertex or index buffer
==============  =======================================================================
"""
from __future__ import annotations

import weakref
from collections import defaultdict

import moderngl

ACCESS = ("sampled", "storage", "attachment", "copy", "indirect", "uniform", "vertex")

# (what is read: "texture" or "buffer", how) -> the barrier bit that makes earlier storage writes visible to it
_BITS = {
    ("texture", "sampled"): moderngl.TEXTURE_FETCH_BARRIER_BIT,
    ("texture", "storage"): moderngl.SHADER_IMAGE_ACCESS_BARRIER_BIT,
    ("texture", "attachment"): moderngl.FRAMEBUFFER_BARRIER_BIT,
    ("texture", "copy"): moderngl.TEXTURE_UPDATE_BARRIER_BIT,
    ("buffer", "sampled"): moderngl.TEXTURE_FETCH_BARRIER_BIT,            # a texel buffer
    ("buffer", "storage"): moderngl.SHADER_STORAGE_BARRIER_BIT,
    ("buffer", "copy"): moderngl.BUFFER_UPDATE_BARRIER_BIT | moderngl.PIXEL_BUFFER_BARRIER_BIT,
    ("buffer", "indirect"): moderngl.COMMAND_BARRIER_BIT,
    ("buffer", "uniform"): moderngl.UNIFORM_BARRIER_BIT,
    ("buffer", "vertex"): moderngl.VERTEX_ATTRIB_ARRAY_BARRIER_BIT | moderngl.ELEMENT_ARRAY_BARRIER_BIT,
}
_ALL = {kind: sum({bits for (k, _), bits in _BITS.items() if k == kind}) for kind in ("texture", "buffer")}

BIT_NAMES = {bit: name.removesuffix("_BARRIER_BIT").lower() for name in dir(moderngl)
             if name.endswith("_BARRIER_BIT") and (bit := getattr(moderngl, name))}
_KIND_BITS = {kind: tuple(bit for bit in sorted(BIT_NAMES) if _ALL[kind] & bit) for kind in _ALL}
_BIT_ORDER = sorted(BIT_NAMES.items())
_KINDS = {moderngl.Buffer: "buffer", **{cls: "texture" for cls in
          (moderngl.Texture, moderngl.Texture3D, moderngl.TextureArray, moderngl.TextureCube)}}


def kind_of(obj) -> str | None:
    """'texture' or 'buffer' for a moderngl texture or buffer, None for anything else (no hazards)."""
    if isinstance(obj, moderngl.Buffer):
        return "buffer"
    if isinstance(obj, (moderngl.Texture, moderngl.Texture3D, moderngl.TextureArray, moderngl.TextureCube)):
        return "texture"
    return None


def barrier_bit(kind: str, access: str) -> int:
    """The barrier bit a use of ``access`` of a ``kind`` ('texture'/'buffer') needs after a storage
    write (0 where the pair cannot occur: a buffer attachment)."""
    if access not in ACCESS:
        raise ValueError(f"access {access!r} is not one of: {', '.join(ACCESS)}")
    return _BITS.get((kind, access), 0)


def bit_names(bits: int) -> list[str]:
    """The names of the barrier bits in ``bits`` (for dumps and tests)."""
    return [name for bit, name in sorted(BIT_NAMES.items()) if bits & bit]


def _uses(items, default_texture: str, default_buffer: str):
    """(obj, kind, access) for each item: an object (default access by kind) or an (obj, access) pair."""
    for item in items:
        obj, access = item if isinstance(item, tuple) else (item, None)
        kind = kind_of(obj)
        if kind is None:
            continue
        access = access or (default_texture if kind == "texture" else default_buffer)
        if access not in ACCESS:
            raise ValueError(f"access {access!r} is not one of: {', '.join(ACCESS)}")
        yield obj, kind, access


class Hazards:
    """The storage writes of one context not yet made visible to every kind of use.

    ``use(reads, writes)`` before work, ``wrote(writes)`` after it (the graph around a pass); binds
    call :meth:`need` and :meth:`stage`, and :func:`dispatch` flushes and commits. ``barriers`` counts the glMemoryBarrier calls issued and
    ``bits_issued`` how often each bit was in one (tests, benchmarks).
    """

    def __init__(self, ctx):
        self._ctx = weakref.ref(ctx)          # the registry is keyed by ctx: a strong ref would keep it alive
        self.barriers = 0
        self._issued: dict[int, int] = defaultdict(int)   # barrier bits -> how many barriers had exactly those
        self._dirty: dict[int, list] = {}     # id(obj) -> [weakref, kind, bits still to issue]
        self._staged: dict[int, tuple] = {}   # bound for a storage write by the coming dispatch: id -> (ref, kind)
        self._need = 0                        # bits the binds of the coming work asked for (issued by flush)
        self._pending = {bit: {} for bit in BIT_NAMES}   # bit -> {id: None} whose entry may still hold it (dicts:
        # filled by subscript, no method call per write)
        self._purge_at = 64                   # entries in _dirty past which dead ones are dropped

    def mark(self, key: int, obj, kind: str) -> None:
        """``obj`` (id ``key``, of ``kind``) was just written by storage: every use's barrier pending."""
        self._dirty[key] = [weakref.ref(obj), kind, _ALL[kind]]
        pending = self._pending
        for bit in _KIND_BITS[kind]:
            pending[bit][key] = None

    def stage(self, obj) -> None:
        """``obj`` is bound for a storage write by the next :meth:`commit`-ed work (a bind does this)."""
        try:
            kind = _KINDS[type(obj)]
        except KeyError:
            kind = kind_of(obj)
            if kind is None:
                return
        self._staged[id(obj)] = (obj, kind)

    def commit(self) -> None:
        """The work just recorded ran: what was staged for writing is now dirty."""
        staged, mark = self._staged, self.mark
        for key in staged:
            obj, kind = staged[key]
            mark(key, obj, kind)
        self._staged = {}

    def use(self, reads=(), writes=()) -> int:
        """Issue the barrier the coming work needs (with what binds asked for): ``reads`` and ``writes``
        are GL objects (textures default to ``sampled`` reads, buffers to ``storage``; writes default to
        ``storage``) or (obj, access) pairs. Returns the bits needed (0: none)."""
        need = 0
        dirty = self._dirty
        for obj, kind, access in _uses(reads, "sampled", "storage"):
            entry = dirty.get(id(obj))
            if entry is not None and entry[0]() is obj:
                need |= entry[2] & _BITS.get((kind, access), 0)
        for obj, kind, access in _uses(writes, "storage", "storage"):
            entry = dirty.get(id(obj))
            if entry is not None and entry[0]() is obj:   # write after a storage write: order the two
                need |= entry[2] & _BITS.get((kind, access), 0)
        if need or self._need:
            self.issue(need | self._need)
        return need

    def need(self, obj, bit: int) -> None:
        """The fast form of a deferred :meth:`use` (what binds call): ``obj`` is used in the way whose
        barrier bit is ``bit`` (:func:`barrier_bit`) by the coming work."""
        entry = self._dirty.get(id(obj))
        if entry is not None and entry[0]() is obj:
            self._need |= entry[2] & bit

    def flush(self) -> None:
        """Issue what the binds of the coming work asked for (dispatches and draws call this)."""
        if self._need:
            self.issue(self._need)

    def wrote(self, writes=()) -> None:
        """The work just recorded wrote ``writes``; those with ``storage`` access are now dirty."""
        for obj, kind, access in _uses(writes, "storage", "storage"):
            if access == "storage":
                self.mark(id(obj), obj, kind)

    def wrote_storage(self, objects) -> None:
        """The work just recorded made storage writes to ``objects`` (textures, buffers): now dirty."""
        dirty, pending = self._dirty, self._pending
        for obj in objects:
            kind = _KINDS[type(obj)] if type(obj) in _KINDS else kind_of(obj)
            if kind is not None:
                key = id(obj)
                dirty[key] = [weakref.ref(obj), kind, _ALL[kind]]     # mark, inlined
                for bit in _KIND_BITS[kind]:
                    pending[bit][key] = None

    def issue(self, bits: int) -> None:
        """One glMemoryBarrier with ``bits``; every pending write is then visible to those uses. The one
        place atmos issues a barrier: moderngl's ``Context.memory_barrier`` made on its C object directly."""
        self._ctx().mglo.memory_barrier(bits, False)
        self._need = 0
        self.barriers += 1
        self._issued[bits] += 1
        dirty, pending, rest, dropped = self._dirty, self._pending, bits, []
        while rest:                           # only the entries that still held an issued bit are touched
            bit = rest & -rest
            rest ^= bit
            keys = pending[bit] if bit in pending else None
            if not keys:
                continue
            for key in keys:
                if key not in dirty:          # (an id reused by an object of the other kind, dropped since)
                    continue
                entry = dirty[key]
                left = entry[2] & ~bit
                if left and entry[0]() is not None:
                    entry[2] = left
                else:
                    dropped += (key,)         # (no method call)
            pending[bit] = {}                 # (a new dict: no method call)
        if len(dirty) > self._purge_at:       # entries of dead objects whose bits are never issued
            dropped += [k for k, e in dirty.items() if e[0]() is None]
            self._purge_at = max(64, 2 * (len(dirty) - len(dropped)))
        for key in dropped:
            if key in dirty:
                kind = dirty[key][1]
                del dirty[key]
                for bit in _KIND_BITS[kind]:
                    keys = pending[bit]
                    if key in keys:
                        del keys[key]

    @property
    def bits_issued(self) -> dict[str, int]:
        """Bit name -> how many of the barriers issued had that bit (0 for a bit never issued)."""
        counts: dict[str, int] = defaultdict(int)
        for bits, n in self._issued.items():
            for bit, name in _BIT_ORDER:
                if bits & bit:
                    counts[name] += n
        return counts

    def settle(self) -> int:
        """Make every pending write visible to every use (for readers that declare nothing: a frame's
        end, a test reading back). Returns the bits issued."""
        need = 0
        for entry in self._dirty.values():
            if entry[0]() is not None:
                need |= entry[2]
        if need:
            self.issue(need)
        else:
            self._dirty.clear()
            for keys in self._pending.values():
                keys.clear()
        return need

    def pending(self, obj) -> list[str]:
        """The uses ``obj``'s last storage write is not yet visible to (bit names; [] when clean)."""
        entry = self._dirty.get(id(obj))
        return bit_names(entry[2]) if entry is not None and entry[0]() is obj else []


_TRACKERS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()   # moderngl.Context -> Hazards
_LAST: list = [None]          # the Hazards looked up last (one context is the common case)


def _tracker(ctx) -> Hazards | None:
    """The Hazards of ``ctx`` where it has one (the last one looked up first)."""
    tracker = _LAST[0]
    if tracker is None or tracker._ctx() is not ctx:
        tracker = _TRACKERS.get(ctx)
        if tracker is not None:
            _LAST[0] = tracker
    return tracker


def hazards_of(ctx) -> Hazards:
    """The one :class:`Hazards` of a moderngl context (``GpuContext.hazards`` is the same object)."""
    tracker = _TRACKERS.get(ctx)
    if tracker is None:
        tracker = _TRACKERS[ctx] = Hazards(ctx)
        _guard_transfers()
    return tracker


def dispatch(program, *groups: int) -> None:
    """Run compute ``program`` over ``groups`` work groups (x[, y[, z]]); what its binds staged for a
    storage write is dirty afterwards (:class:`Hazards`). The one way atmos runs a compute program."""
    extra = program.extra
    hazards = extra["hazards"] if type(extra) is dict and "hazards" in extra else hazards_of(program.ctx)
    if hazards._need:
        hazards.issue(hazards._need)
    program.run(*groups)
    staged = hazards._staged
    if staged:                                   # Hazards.commit, inlined (a dispatch without storage writes skips it)
        dirty, pending = hazards._dirty, hazards._pending
        for key in staged:
            obj, kind = staged[key]
            dirty[key] = [weakref.ref(obj), kind, _ALL[kind]]     # Hazards.mark, inlined
            for bit in _KIND_BITS[kind]:
                pending[bit][key] = None
        hazards._staged = {}


def dispatch_indirect(program, args, offset: int = 0) -> None:
    """Run compute ``program`` with its group counts read on the GPU from buffer ``args`` (3 uints at
    ``offset``), after the barrier that makes a shader's write of ``args`` visible as indirect arguments."""
    extra = program.extra
    hazards = extra["hazards"] if type(extra) is dict and "hazards" in extra else hazards_of(program.ctx)
    dirty = hazards._dirty                               # Hazards.need, inlined
    if dirty and (key := id(args)) in dirty and (entry := dirty[key])[0]() is args:
        hazards._need |= entry[2] & moderngl.COMMAND_BARRIER_BIT
    if hazards._need:                                    # with what the binds asked for: one barrier
        hazards.issue(hazards._need)
    program.run_indirect(args, offset)
    staged = hazards._staged
    if staged:                                   # Hazards.commit, inlined
        dirty, pending = hazards._dirty, hazards._pending
        for key in staged:
            obj, kind = staged[key]
            dirty[key] = [weakref.ref(obj), kind, _ALL[kind]]     # Hazards.mark, inlined
            for bit in _KIND_BITS[kind]:
                pending[bit][key] = None
        hazards._staged = {}


_GUARDED = False
_TRANSFERS = {   # moderngl methods that read or write an object's memory from the CPU side: 'copy' uses
    moderngl.Buffer: ("read", "read_into", "write", "write_chunks", "clear", "orphan"),
    **{cls: ("read", "read_into", "write") for cls in
       (moderngl.Texture, moderngl.Texture3D, moderngl.TextureArray, moderngl.TextureCube)},
}
_BUILD_MIPMAPS = {cls: ("build_mipmaps",) for cls in
                  (moderngl.Texture, moderngl.Texture3D, moderngl.TextureArray, moderngl.TextureCube)}


def _guard_transfers() -> None:
    """Wrap moderngl's CPU transfers once per process so that each is a declared ``copy`` use: a
    readback (the game's or a test's included) sees the storage writes before it, an upload waits for them."""
    global _GUARDED
    if _GUARDED:
        return
    _GUARDED = True
    for name in ("render", "render_indirect"):
        method = getattr(moderngl.VertexArray, name)
        if not getattr(method, "_atmos_copy_use", False):
            setattr(moderngl.VertexArray, name, _flushing(method))
    for table, uses in ((_TRANSFERS, ("copy",)), (_BUILD_MIPMAPS, ("copy", "sampled"))):
        for cls, names in table.items():
            for name in names:
                method = getattr(cls, name, None)
                if method is not None and not getattr(method, "_atmos_copy_use", False):
                    setattr(cls, name, _copy_use(method, uses))


def _flushing(method):
    """A draw: the barrier its binds asked for, then the draw."""
    def draw(self, *args, **kwargs):
        tracker = _LAST[0]
        if tracker is None or tracker._ctx() is not self.ctx:
            tracker = _tracker(self.ctx)
        if tracker is not None and tracker._need:
            tracker.issue(tracker._need)
        return method(self, *args, **kwargs)
    draw._atmos_copy_use = True
    draw.__name__, draw.__qualname__, draw.__doc__ = method.__name__, method.__qualname__, method.__doc__
    draw.__wrapped__ = method
    return draw


def _copy_use(method, uses):
    bits = {kind: sum({_BITS.get((kind, access), 0) for access in uses}) for kind in ("texture", "buffer")}

    def transfer(self, *args, **kwargs):
        tracker = _LAST[0]
        if tracker is None or tracker._ctx() is not self.ctx:
            tracker = _tracker(self.ctx)
        if tracker is not None:
            entry = tracker._dirty.get(id(self))       # Hazards.use of (self, each of uses), inlined
            if entry is not None and entry[0]() is self:
                need = (entry[2] & bits[entry[1]]) | tracker._need
                if need:
                    tracker.issue(need)
        return method(self, *args, **kwargs)
    transfer._atmos_copy_use = True
    transfer.__name__, transfer.__qualname__, transfer.__doc__ = method.__name__, method.__qualname__, method.__doc__
    transfer.__wrapped__ = method
    return transfer
