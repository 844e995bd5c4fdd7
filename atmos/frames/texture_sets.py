"""The three texture sets of a simulation that is computed a few slices per frame.

A and B hold the last two completed results and are what readers draw (interpolated); C is the
set the slices of the current step write into. When C is complete the sets rotate
(A←B, B←C, C←old A), so no texture is ever read while it is half written.

Texture descriptions are duck-typed: any object with ``size`` ((w, h) or (w, h, d)),
``components``, ``dtype``, ``depth`` and ``filter`` works, ``atmos.graph.resources.TextureDesc``
included.
"""
from __future__ import annotations

from typing import Iterator, Mapping

import moderngl

_DTYPE_BYTES = {"f1": 1, "u1": 1, "i1": 1, "f2": 2, "u2": 2, "i2": 2, "f4": 4, "u4": 4, "i4": 4}
_FILTERS = {"linear": (moderngl.LINEAR, moderngl.LINEAR), "nearest": (moderngl.NEAREST, moderngl.NEAREST)}


def _describe(desc) -> str:
    return f"{type(desc).__name__}(size={getattr(desc, 'size', '?')}, dtype={getattr(desc, 'dtype', '?')!r})"


def make_texture(gpu, desc, clear: bool = True):
    """A moderngl texture for ``desc``, tracked by ``gpu`` (released with it).

    2D sizes give ``ctx.texture`` (or ``ctx.depth_texture`` when ``desc.depth``), 3D sizes
    ``ctx.texture3d``. ``filter`` is ``"linear"`` or ``"nearest"``. Colour textures are filled
    with zeros when ``clear`` is true, so a set never holds undefined data.
    """
    size = tuple(int(s) for s in getattr(desc, "size", ()))
    components = int(getattr(desc, "components", 4))
    dtype = getattr(desc, "dtype", "f2")
    depth = bool(getattr(desc, "depth", False))
    filter_name = getattr(desc, "filter", "linear")
    if len(size) not in (2, 3) or any(s < 1 for s in size):
        raise ValueError(f"texture size {getattr(desc, 'size', None)!r} in {_describe(desc)}: "
                         "allowed are (width, height) or (width, height, depth), each at least 1")
    if filter_name not in _FILTERS:
        raise ValueError(f"texture filter {filter_name!r} in {_describe(desc)}: allowed are 'linear', 'nearest'")
    if depth:
        if len(size) != 2:
            raise ValueError(f"depth texture {_describe(desc)} must be 2D: 3D depth textures are not supported")
        texture = gpu.ctx.depth_texture(size)
    else:
        if dtype not in _DTYPE_BYTES:
            raise ValueError(f"texture dtype {dtype!r} in {_describe(desc)}: allowed are {', '.join(_DTYPE_BYTES)}")
        if components not in (1, 2, 3, 4):
            raise ValueError(f"texture components {components} in {_describe(desc)}: allowed are 1, 2, 3, 4")
        if len(size) == 2:
            texture = gpu.ctx.texture(size, components, dtype=dtype)
        else:
            texture = gpu.ctx.texture3d(size, components, dtype=dtype)
        if clear:
            texels = 1
            for s in size:
                texels *= s
            texture.write(bytes(texels * components * _DTYPE_BYTES[dtype]))
    texture.filter = _FILTERS[filter_name]
    return gpu.track(texture)


class TextureSet:
    """Named textures of one completed (or in-progress) result: ``textures[name]`` or ``set[name]``."""

    def __init__(self, textures: Mapping[str, object], label: str = ""):
        self.textures: dict[str, object] = dict(textures)
        self.label = label

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

    def release(self) -> None:
        for texture_set in (self.a, self.b, self.c):
            texture_set.release()

    def __repr__(self) -> str:
        return f"TripleSet(generation={self.generation}, a={self.a.label}, b={self.b.label}, c={self.c.label})"
