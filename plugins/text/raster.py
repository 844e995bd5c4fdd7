"""Text to coverage bitmaps with Pillow's FreeType renderer (its bundled font by default, or a TrueType
/ OpenType file): the same pixels in a window and headless."""
from __future__ import annotations

from functools import lru_cache

import numpy as np


@lru_cache(maxsize=16)
def font(path: str | None, size: int):
    """The Pillow font of ``size`` pixels: ``path`` (a .ttf/.otf file) or Pillow's bundled font."""
    from PIL import ImageFont
    if path is None:
        return ImageFont.load_default(size=size)
    try:
        return ImageFont.truetype(path, size)
    except OSError as error:
        raise ValueError(f"TextPlugin.font must be a TrueType/OpenType font file or None; cannot load {path!r} "
                         f"({error})") from None


def rasterize(text: str, size: int, path: str | None = None) -> np.ndarray:
    """uint8 (h, w) anti-aliased coverage of ``text`` (lines split at newlines), rows top-down, a
    pixel of margin around; at least 1×1 (empty text)."""
    from PIL import Image, ImageDraw
    f = font(path, size)
    lines = text.split("\n")
    ascent, descent = f.getmetrics()
    line_height = ascent + descent
    width = max([int(np.ceil(f.getlength(line))) for line in lines] + [1]) + 2
    image = Image.new("L", (width, line_height * len(lines) + 2), 0)
    draw = ImageDraw.Draw(image)
    for i, line in enumerate(lines):
        draw.text((1, 1 + i * line_height), line, font=f, fill=255)
    return np.asarray(image)
