"""Four tileable octave textures of 2D value noise, baked on the GPU (``core/tile_octave.comp``): the sky
layer's clouds and the cloud far field's cover both stand on them. Channel c of a texel holds the
noise ``steps[c]`` light steps toward the sun, so one fetch gives a short light march."""
from __future__ import annotations

import math

import moderngl
import numpy as np

from atmos.gpu.uniforms import bind_images, bind_textures
from atmos.value_noise import key, value_noise
from atmos.gpu.hazards import dispatch

WEIGHTS = np.array([0.5, 0.25, 0.125, 0.0625])      # the octaves' fbm weights


def octave_key(seed: int, octave: int) -> int:
    """The lattice key of octave ``octave`` (a different noise per octave)."""
    return int(key((seed + 0x9E3779B1 * octave) % 2**32))


def tile_noise(uv: np.ndarray, frequency: float, k) -> np.ndarray:
    """4D value noise on two circles of radius frequency/2π: periodic with period 1 in u and v
    (what ``core/tile_octave.comp`` bakes; float64)."""
    a = 2 * np.pi * np.asarray(uv, np.float64)
    r = frequency / (2 * np.pi)
    x = r * np.stack([np.cos(a[..., 0]), np.sin(a[..., 0]), np.cos(a[..., 1]), np.sin(a[..., 1])], axis=-1)
    return value_noise(x, k)


def light_shift(sun_dir, light_step: float) -> np.ndarray:
    """uv step toward the sun: light_step along the sun's horizontal direction (0 with the sun overhead)."""
    xz = np.array([sun_dir[0], sun_dir[2]], np.float64)
    n = math.sqrt(xz.dot(xz))   # np.linalg.norm's own formula (1-D float64), without its overhead
    return xz / n * light_step if n > 1e-6 else np.zeros(2)


OCTAVES = 4


class OctaveTextures:
    """Four RGBA float textures (repeat, mipmapped); octave k has base_frequency·2^k cells per tile and
    channel c its noise ``steps[c]`` light steps toward the sun (:meth:`bake`; the sky layer's light
    march: c steps). :meth:`bake` (re)computes them."""

    def __init__(self, gpu):
        self.gpu = gpu
        self.textures: list = []
        self.bakes = 0
        self.baked_for: tuple | None = None    # (texture settings, light shift) of the last bake
        self._program = None

    def bake(self, settings, sun_dir, frequencies=None, shift_maps=None,
             steps=(0.0, 1.0, 2.0, 3.0)) -> None:
        """Fill the textures for ``settings`` and the sun direction (re-allocating on a size change).
        ``frequencies`` (4,): cells across each texture (default base_frequency·2^k); ``shift_maps``
        (4, 2, 2): each texture's light shift is shift_maps[k] @ the sun's (default: the same for all);
        ``steps`` (4,): the light steps toward the sun each channel holds the noise at. ``settings``: any
        with ``size``, ``base_frequency``, ``seed``, ``light_step`` and ``texture_key()`` (the sky
        layer's and the far field's)."""
        ctx = self.gpu.ctx
        if self._program is None:
            self._program = self.gpu.program(compute_shader="core/tile_octave.comp")
        if not self.textures or self.textures[0].size != (settings.size, settings.size):
            self.release()
            for _ in range(OCTAVES):
                tex = self.gpu.track(ctx.texture((settings.size, settings.size), 4, dtype="f4"))
                tex.repeat_x = tex.repeat_y = True
                self.textures.append(tex)
        shift = light_shift(sun_dir, settings.light_step)
        prog = self._program
        prog["light_shift"].value = tuple(shift)
        prog["channel_steps"].value = tuple(float(v) for v in steps)
        groups = math.ceil(settings.size / 8)
        for k, tex in enumerate(self.textures):
            prog["frequency"].value = float(settings.base_frequency * 2 ** k if frequencies is None else frequencies[k])
            if shift_maps is not None:
                prog["light_shift"].value = tuple(np.asarray(shift_maps[k], np.float64) @ shift)
            prog["key"].value = octave_key(settings.seed, k)
            bind_images(prog, octave=tex)
            dispatch(prog, groups, groups)
        for tex in self.textures:
            tex.build_mipmaps()
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
        self.bakes += 1
        self.baked_for = (settings.texture_key(), tuple(shift))

    def needs_bake(self, settings, sun_dir, tolerance: float) -> bool:
        """True before the first bake, after a texture setting changed, or once the light shift moved by
        more than ``tolerance`` of a light step (the sun turned)."""
        if self.baked_for is None or self.baked_for[0] != settings.texture_key():
            return True
        shift = light_shift(sun_dir, settings.light_step) - self.baked_for[1]
        moved = math.sqrt(shift.dot(shift))   # np.linalg.norm's own formula (1-D float64), without its overhead
        return moved > tolerance * settings.light_step

    def download(self, k: int) -> np.ndarray:
        """Octave ``k`` as float64 (size, size, 4) indexed [x, y, channel]."""
        tex = self.textures[k]
        w, h = tex.size
        return np.frombuffer(tex.read(), np.float32).reshape(h, w, 4).transpose(1, 0, 2).astype(np.float64)

    def bind(self, program) -> None:
        """Bind octave k to the program's sampler ``octave{k}``."""
        bind_textures(program, {f"octave{k}": tex for k, tex in enumerate(self.textures)})

    def release(self) -> None:
        for tex in self.textures:
            tex.release()
        self.textures = []
        self.baked_for = None
