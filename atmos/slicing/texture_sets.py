"""The three texture sets of a simulation that is computed a few slices per frame.

A and B hold the last two completed results and are what readers draw (interpolated); C is the
set the slices of the current step write into. When C is complete the sets rotate
(A←B, B←C, C←old A), so no texture is ever read while it is half written.

Textures are described by :class:`atmos.graph.TextureDesc`, as the render graph's are.
"""
from __future__ import annotations

from typing import Iterator, Mapping

from atmos.graph.resources import TextureDesc

def make_texture(gpu, desc: TextureDesc, clear: bool = True):
    """A zero-filled moderngl texture for ``desc``, tracked by ``gpu`` (released with it)."""
    if not isinstance(desc, TextureDesc):
        raise ValueError(f"texture description {desc!r}: allowed is an atmos.graph.TextureDesc")
    return gpu.track(desc.create(gpu.ctx, clear=clear))


class TextureSet:
    """Named textures of one completed (or in-progress) result: ``textures[name]`` or ``set[name]``.

    ``version`` counts the times its contents were made anew as a whole (:meth:`TripleSet.rotate` for the
    new B, a static set re-shaded): what a reader derives from a set once it keeps under (set, version)."""

    def __init__(self, textures: Mapping[str, object], label: str = ""):
        self.textures: dict[str, object] = dict(textures)
        self.label = label
        self.version = 0

    @classmethod
    def create(cls, gpu, descs: Mapping[str, object], label: str = "") -> "TextureSet":
        """One texture per entry of ``descs`` (name → description)."""
        return cls({name: make_texture(gpu, desc) for name, desc in descs.items()}, label)

    def __getitem__(self, name: str):
        try:
            return self.textures[name]
        except KeyError:
            raise KeyError(f"texture set {self.label or '?'} has no texture {name!r}; "
                           f"it has: {', '.join(self.textures) or 'none'}") from None

    def __contains__(self, name: object) -> bool:
        return name in self.textures

    def ensure(self, gpu, name: str, desc: TextureDesc):
        """The texture ``name``, made (zero-filled) from ``desc`` if the set has none yet: a texture
        only some steps need (released again with :meth:`drop`)."""
        if name not in self.textures:
            self.textures[name] = make_texture(gpu, desc)
        return self.textures[name]

    def drop(self, name: str) -> None:
        """Release and remove the texture ``name`` if the set has one."""
        texture = self.textures.pop(name, None)
        if texture is not None:
            texture.release()

    def __iter__(self) -> Iterator[str]:
        return iter(self.textures)

    def __len__(self) -> int:
        return len(self.textures)

    def release(self) -> None:
        for texture in self.textures.values():
            texture.release()

    def __repr__(self) -> str:
        return f"TextureSet({self.label!r}, {list(self.textures)})"


class TripleSet:
    """Three :class:`TextureSet` of the same descriptions: ``a`` and ``b`` are shown, ``c`` is written.

    ``rotate()`` moves A←B, B←C, C←old A and counts ``generation``.
    """

    def __init__(self, gpu, descs: Mapping[str, object]):
        if not descs:
            raise ValueError("TripleSet needs at least one texture description (name → TextureDesc); got none")
        self.gpu = gpu
        self.descs = dict(descs)
        self.a, self.b, self.c = (TextureSet.create(gpu, self.descs, label) for label in ("0", "1", "2"))
        self.generation = 0

    @property
    def sets(self) -> tuple[TextureSet, TextureSet, TextureSet]:
        """(A, B, C) in their current roles."""
        return self.a, self.b, self.c

    def rotate(self) -> None:
        """A←B, B←C, C←old A: the just-completed C becomes the newest shown result."""
        self.a, self.b, self.c = self.b, self.c, self.a
        self.generation += 1
        self.b.version += 1

    def release(self) -> None:
        for texture_set in (self.a, self.b, self.c):
            texture_set.release()

    def __repr__(self) -> str:
        return f"TripleSet(generation={self.generation}, a={self.a.label}, b={self.b.label}, c={self.c.label})"
