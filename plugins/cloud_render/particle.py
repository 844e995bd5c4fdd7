"""The soft particle every cloud sprite is drawn with: ``(1 − r²)²`` inside the unit disc, 0 outside.

Its integral over the unit disc is π/3, so a sprite of world diameter ``D`` spreads ``π D² / 12``
times its centre optical depth over the screen; the renderer divides by that (see ``plugin``).
"""
from __future__ import annotations

import math

import moderngl
import numpy as np

PROFILE_AREA = math.pi / 3.0        # ∫ (1 − r²)² dA over the unit disc


def particle_profile(n: int = 64) -> np.ndarray:
    """(n, n) float32 falloff sampled at texel centres (r = 1 at the texture's inscribed circle)."""
    c = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    r2 = c[:, None] ** 2 + c[None, :] ** 2
    return np.where(r2 < 1.0, (1.0 - r2) ** 2, 0.0).astype(np.float32)


def particle_texture(ctx: moderngl.Context, n: int = 64):
    """The profile as an r32f linear-filtered, edge-clamped 2D texture (made once per pass)."""
    texture = ctx.texture((n, n), 1, particle_profile(n).tobytes(), dtype="f4")
    texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
    texture.repeat_x = texture.repeat_y = False
    return texture
