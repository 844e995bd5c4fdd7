"""Transient texture and buffer descriptions and the pool that recycles them between passes and frames."""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import moderngl

DTYPES = ("f1", "f2", "f4", "u1", "u2", "u4", "i1", "i2", "i4")
FILTERS = ("linear", "nearest")


@dataclass(frozen=True)
class TextureDesc:
    """What a transient texture looks like; equal descs share pooled textures (it is the pool key).

    ``size`` is (w, h) or (w, h, d) for a 3D texture. A ``depth`` texture must be 2D and ignores
    ``components``/``dtype``. Integer dtypes (``u*``, ``i*``) need ``filter="nearest"``. ``storage``:
    a compute pass writes it as an image (``layout(r32f)``, ``rgba16f``...): 1, 2 or 4 components
    (image formats have no 3-component kind), not depth — a depth made by compute is ``components=1,
    dtype="f4"`` (``r32f``).
    """

    size: tuple[int, ...]
    components: int = 4
    dtype: str = "f2"
    depth: bool = False
    filter: str = "linear"
    storage: bool = False

    def __post_init__(self):
        size = self.size
        plain = type(size) is tuple and len(size) in (2, 3)      # a tuple of positive ints: kept as it is
        if plain:
            for s in size:
                if type(s) is not int or s < 1:
                    plain = False
        if not plain:
            try:
                size = tuple(int(s) for s in self.size)
            except (TypeError, ValueError):
                raise ValueError(f"TextureDesc.size must be (w, h) or (w, h, d) of positive ints, got {self.size!r}") from None
            if len(size) not in (2, 3) or min(size) < 1 or any(s != o for s, o in zip(size, self.size)):
                raise ValueError(f"TextureDesc.size must be (w, h) or (w, h, d) of positive ints, got {self.size!r}")
            object.__setattr__(self, "size", size)
        if self.components not in (1, 2, 3, 4):
            raise ValueError(f"TextureDesc.components must be 1, 2, 3 or 4, got {self.components!r}")
        if self.dtype not in DTYPES:
            raise ValueError(f"TextureDesc.dtype must be one of {', '.join(DTYPES)}, got {self.dtype!r}")
        if self.filter not in FILTERS:
            raise ValueError(f"TextureDesc.filter must be 'linear' or 'nearest', got {self.filter!r}")
        if self.depth and len(size) != 2:
            raise ValueError(f"a depth TextureDesc must have a 2D size (w, h), got {size!r}")
        if not self.depth and self.dtype[0] in "ui" and self.filter != "nearest":
            raise ValueError(f"integer TextureDesc dtype {self.dtype!r} needs filter='nearest' "
                             "(OpenGL cannot filter integer textures linearly)")
        if self.storage and (self.depth or self.components == 3):
            raise ValueError(f"a storage TextureDesc (written as an image) must have 1, 2 or 4 components and "
                             f"not be depth, got components={self.components}, depth={self.depth}; a depth "
                             "made by compute is components=1, dtype='f4' (r32f)")
        key = (TextureDesc, self.size, self.components, self.dtype, self.depth, self.filter, self.storage)
        object.__setattr__(self, "key", key)          # the pool's key: a tuple, hashed and compared in C
        object.__setattr__(self, "_hash", hash(key))

    def __hash__(self) -> int:
        """The fields' hash, worked out once (a desc is the pool's key, looked up every frame)."""
        return self._hash

    def __reduce__(self):                  # made anew from the fields: the hash of str differs between processes
        return TextureDesc, (self.size, self.components, self.dtype, self.depth, self.filter, self.storage)

    @property
    def nbytes(self) -> int:
        """GL memory of one such texture in bytes (approximate for depth)."""
        texels = 1
        for s in self.size:
            texels *= s
        return texels * (4 if self.depth else self.components * int(self.dtype[1]))

    def create(self, ctx: moderngl.Context, clear: bool = False):
        """A new moderngl texture of this description (colour textures zero-filled when ``clear``)."""
        if self.depth:
            texture = ctx.depth_texture(self.size)
            texture.compare_func = ""  # sample as a plain sampler2D
        elif len(self.size) == 3:
            texture = ctx.texture3d(self.size, self.components, dtype=self.dtype)
        else:
            texture = ctx.texture(self.size, self.components, dtype=self.dtype)
        if clear and not self.depth:
            texels = 1
            for s in self.size:
                texels *= s
            texture.write(bytes(texels * self.components * int(self.dtype[1])))
        mode = moderngl.LINEAR if self.filter == "linear" else moderngl.NEAREST
        texture.filter = (mode, mode)
        return texture

    def __str__(self) -> str:
        size = "x".join(map(str, self.size))
        if self.depth:
            return f"{size} depth {self.filter}"
        return f"{size} {self.components}x{self.dtype} {self.filter}" + (" storage" if self.storage else "")


@lru_cache(maxsize=32)
def _zeros(size: int) -> bytes:
    return bytes(size)


@dataclass(frozen=True)
class BufferDesc:
    """A transient GPU buffer of ``size`` bytes (a compute pass's list, counters or indirect arguments);
    equal descs share pooled buffers. ``clear``: zero-filled each time a pass creates it."""

    size: int
    clear: bool = False

    def __post_init__(self):
        if isinstance(self.size, bool) or not isinstance(self.size, int) or self.size < 1:
            raise ValueError(f"BufferDesc.size must be a positive int (bytes), got {self.size!r}")
        if not isinstance(self.clear, bool):
            raise ValueError(f"BufferDesc.clear must be True or False, got {self.clear!r}")
        key = (BufferDesc, self.size, self.clear)
        object.__setattr__(self, "key", key)          # the pool's key: a tuple, hashed and compared in C
        object.__setattr__(self, "_hash", hash(key))

    def __hash__(self) -> int:
        """The fields' hash, worked out once (a desc is the pool's key)."""
        return self._hash

    def __reduce__(self):
        return BufferDesc, (self.size, self.clear)

    @property
    def nbytes(self) -> int:
        return self.size

    @property
    def zeros(self) -> bytes:
        """``size`` zero bytes (what a cleared buffer is filled with), made once per size."""
        return _zeros(self.size)

    def create(self, ctx: moderngl.Context, clear: bool = False):
        """A new moderngl buffer of this size (zero-filled)."""
        return ctx.buffer(reserve=self.size)

    def __str__(self) -> str:
        return f"buffer {self.size} B" + (" cleared" if self.clear else "")


class TexturePool:
    """Textures and buffers keyed by :class:`TextureDesc` / :class:`BufferDesc`: ``acquire`` reuses a
    free one of an equal desc, else creates one.

    :meth:`end_frame` (the graph calls it after each frame) releases the GL memory of free textures
    that no frame acquired or released during the last ``keep_frames`` frames, so descs that stop
    being used (old window sizes, a changed setting) do not pile up. In-use textures are never evicted.
    """

    def __init__(self, gpu, keep_frames: int = 3):
        if isinstance(keep_frames, bool) or not isinstance(keep_frames, int) or keep_frames < 1:
            raise ValueError(f"TexturePool keep_frames={keep_frames!r}: allowed is an int >= 1 (frames a free "
                             "texture is kept after its last use before its GL memory is released)")
        self.gpu = gpu
        self.keep_frames = keep_frames
        self.frame = 0        # frames ended so far (end_frame calls)
        self.allocations = 0  # textures ever created
        self.evictions = 0    # textures released by end_frame
        self._free: dict[tuple, list] = {}      # desc.key -> free textures (buffers) of that desc
        self._desc: dict[int, tuple[TextureDesc, object]] = {}  # id(texture) -> (desc, texture), all pooled
        self._in_use: dict[int, object] = {}    # id(texture) -> texture, acquired and not released
        self._used: dict[int, int] = {}  # id(texture) -> frame it was last acquired or released

    def acquire(self, desc: TextureDesc | BufferDesc):
        """A texture (or buffer) matching ``desc``, free until :meth:`release` gives it back."""
        try:
            texture = self._free[desc.key].pop()
        except (KeyError, IndexError):
            texture = self._create(desc)
        if type(desc) is BufferDesc and desc.clear:
            texture.write(desc.zeros)       # glBufferSubData: queued (moderngl's clear() maps it, waiting for the GPU)
        key = id(texture)
        self._in_use[key] = texture
        self._used[key] = self.frame
        return texture

    def release(self, texture) -> None:
        """Give ``texture`` back to the free list of its desc."""
        key = id(texture)
        if key not in self._desc:
            raise ValueError("TexturePool.release: this texture was not acquired from this pool")
        if key not in self._in_use:
            raise ValueError("TexturePool.release: this texture was already released")
        del self._in_use[key]
        self._used[key] = self.frame
        desc = self._desc[key][0].key
        try:
            self._free[desc].append(texture)
        except KeyError:
            self._free[desc] = [texture]

    def end_frame(self) -> int:
        """End a frame: release every free texture not acquired (or released) during the last
        ``keep_frames`` frames, counting this one. Returns how many were released."""
        evicted = 0
        stale = self.frame - self.keep_frames  # last used at or before this frame: evict
        used = self._used
        for desc, free in list(self._free.items()):
            for t in free:
                if used[id(t)] <= stale:
                    break
            else:
                continue                     # every free one used lately
            for texture in [t for t in free if used[id(t)] <= stale]:
                del self._desc[id(texture)], used[id(texture)]
                texture.release()
                evicted += 1
            free[:] = [t for t in free if id(t) in used]
            if not free:
                del self._free[desc]
        self.frame += 1
        self.evictions += evicted
        return evicted

    @property
    def textures(self) -> int:
        """Textures the pool holds now (free and in use)."""
        return len(self._desc)

    @property
    def in_use(self) -> int:
        """Textures acquired and not yet released."""
        return len(self._in_use)

    @property
    def bytes(self) -> int:
        """GL memory of the textures the pool holds now (free and in use), in bytes (approximate for depth)."""
        return sum(desc.nbytes for desc, _ in self._desc.values())

    def release_all(self) -> None:
        """Free the GL memory of every pooled texture, free or in use; the pool starts empty again."""
        for _, texture in self._desc.values():
            texture.release()
        self._free.clear()
        self._desc.clear()
        self._in_use.clear()
        self._used.clear()

    def _create(self, desc: TextureDesc):
        texture = desc.create(self.gpu.ctx)
        self.allocations += 1
        self._desc[id(texture)] = (desc, texture)
        return texture
