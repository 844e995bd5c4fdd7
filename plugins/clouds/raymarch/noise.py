"""The ray march's detail noise: two tileable 3D textures built once per GPU context on the GPU
(``shaders/clouds/raymarch/noise.comp``), and the uniform block of ``shaders/clouds/raymarch/detail.glsl``.

* ``base`` (``base_size``^3, default 128^3): R = Perlin–Worley (Perlin FBM at 4 cells per tile dilated
  by the Worley FBM at 4), G/B/A = Worley FBM at 4, 8 and 16 cells per tile (1×, 2×, 4×).
* ``detail`` (``detail_size``^3, default 32^3): R/G/B = Worley FBM at 2, 4 and 8 cells per tile; A = 1.

The definitions, in float64: :mod:`atmos.plugins.clouds.raymarch.noise_reference`. Both are RGBA8
(4 bytes a texel: 8 MiB + 128 KiB at the defaults; half of RGBA16F, and the march reads them at every
sample): the values are in [0, 1] and an 8-bit step (0.004) is far below what the erosion shows.
Repeat wrap, linear filter, no mipmaps (``detail.glsl`` samples level 0).

:meth:`DetailNoise.bind` sets the uniforms from the march's settings (``RaymarchCloudSettings``):
the base tile ``scale`` in m (``detail_scale`` cells × the cell; the detail tile is
``scale / DETAIL_RATIO``: at the default 8 cells of 40 m, Perlin–Worley billows of 80 m (R, G) down
to 20 m (A) and detail cells of 20, 10 and 5 m), ``strength`` (0..1, 0 = d itself) and, as the define
``DETAIL_OCTAVES`` (:func:`detail_defines`), ``detail_octaves`` (0..3: 0 no read, 1 and 2 one RGBA8
3D read per call, 3 two). The wind (m/s) and the time (s) scroll both textures. Each band fades out
as the pixel grows past its features (:func:`detail_fade`), so far clouds keep the smooth shape.
"""
from __future__ import annotations

import math
import struct
import time as _time
import weakref

import moderngl
import numpy as np

from atmos.gpu.context import GpuContext, require_gpu
from atmos.gpu.uniforms import bind_images, bind_textures, write_block
from atmos.gpu.hazards import dispatch

NOISE_RULE = 0xC1D           # stream id of the noise's hashes: stream_key(seed, 0, NOISE_RULE, plane)
PERLIN_GAIN = 1.5            # Perlin FBM -> [0, 1]: clamp(0.5 + 0.5 GAIN fbm)
DETAIL_RATIO = 8             # base tile / detail tile
PW_RANGE = (0.45, 0.85)      # stored channels: clamp((v - lo) / (hi - lo)) of the raw noise, so the
WORLEY_RANGE = (0.2, 0.75)   # 8 bits and the erosion thresholds span [0, 1] (~0.5 % clipped each end)
COVERAGE = 0.6              # detail.glsl's K: densities at or above it are a cloud's body, never eroded
DETAIL_BLOCK, DETAIL_BINDING = "Detail", 4   # detail.glsl's block of the noise's scroll and settings
_DETAIL_LAYOUT = struct.Struct("<3ff3ff2ff3f8x")   # its std140 layout (64 bytes)
BAND_STRENGTH = 0.5          # the detail band (octave 3) erodes by BAND_STRENGTH × detail_strength
BAND_WIDTH = 0.25            # W: at full strength the shape band remaps coverage e..e + W to 0..1
DETAIL_FADE = (1 / 16, 1 / 4)   # a band's strength fades from 1 to 0 as the pixel's width grows over this many of its tiles
BASE_LAYOUT = (0, 4, (4, 8, 16))     # (texture index, Perlin frequency, Worley FBM frequencies)
DETAIL_LAYOUT = (1, 0, (2, 4, 8))    # Perlin frequency 0: no Perlin–Worley; A = 1
SIZES = (4, 8, 16, 32, 64, 128, 256)

_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()   # GpuContext -> {(sizes, seed): textures}


def detail_offsets(time: float, wind, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """The wind's scroll wind·time in base-tile and detail-tile units, reduced to [0, 1) in float64
    (so the shader's coordinates keep their precision however long the game runs)."""
    shift = np.asarray(wind, np.float64) * float(time) / float(scale)
    return shift % 1.0, (shift * DETAIL_RATIO) % 1.0


def band_width(strength: float) -> float:
    """w = 1 - (1 - BAND_WIDTH) strength: the width the shape band remaps (1 at strength 0: d itself)."""
    return 1.0 - (1.0 - BAND_WIDTH) * float(strength)


def detail_fade(footprint, tile):
    """detail.glsl's keep: the share of a noise band's strength left where a pixel is ``footprint`` m
    wide, for the band's ``tile`` (m): 1 up to DETAIL_FADE[0] tiles, 0 from DETAIL_FADE[1] (noise
    finer than the pixel would alias: stripes and crawling edges on far clouds), linear between."""
    lo, hi = DETAIL_FADE
    return 1.0 - np.clip((np.asarray(footprint, np.float64) / tile - lo) / (hi - lo), 0.0, 1.0)


def pixel_angle(view) -> float:
    """A full-res pixel's angle (rad) for the SceneView ``view``: its width per metre of distance."""
    return 2.0 * math.tan(view.camera.fov_y / 2) / max(view.size[1], 1)


def detail_defines(octaves: int) -> dict:
    """The define ``detail.glsl`` reads: how many noise bands erode the density (0..3)."""
    return {"DETAIL_OCTAVES": int(octaves)}


def _check_size(name: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or int(value) not in SIZES:
        raise ValueError(f"DetailNoise.{name} must be a power of two in 4..256 (texels per tile side), "
                         f"got {value!r}")
    return int(value)


class DetailNoise:
    """The two noise textures of one GPU context (``base``, ``detail``: moderngl 3D textures).

    ``DetailNoise(gpu, base_size=128, detail_size=32, seed=0)`` builds them on the first request for
    these sizes and seed on ``gpu`` and hands out the same textures afterwards (``built`` says whether
    this request built them, ``build_seconds`` how long that took). The context owns them: they are
    released by ``gpu.release()``, never by their users (as the programs of ``gpu.program``).
    """

    def __init__(self, gpu: GpuContext, base_size: int = 128, detail_size: int = 32, seed: int = 0):
        self.gpu = require_gpu(gpu)
        gpu.make_current()                   # a released context is a clear GpuError here
        self.base_size = _check_size("base_size", base_size)
        self.detail_size = _check_size("detail_size", detail_size)
        if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2**32:
            raise ValueError(f"DetailNoise.seed must be a whole number in 0..2**32-1, got {seed!r}")
        self.seed = int(seed)
        key = (self.base_size, self.detail_size, self.seed)
        textures = _CACHE.setdefault(gpu, {})
        self.built = key not in textures
        self.build_seconds = 0.0
        if self.built:
            start = _time.perf_counter()
            textures[key] = self._build()
            self.build_seconds = _time.perf_counter() - start
        self.base, self.detail = textures[key]

    def _build(self) -> tuple:
        gpu = self.gpu
        defines = {"NOISE_RULE": f"{NOISE_RULE}u", "PERLIN_GAIN": repr(PERLIN_GAIN),
                   "PW_RANGE": f"vec2{PW_RANGE}", "WORLEY_RANGE": f"vec2{WORLEY_RANGE}"}
        program = gpu.program(compute_shader="clouds/raymarch/noise.comp", defines=defines)
        made = []
        try:
            for size, (index, perlin, worley) in ((self.base_size, BASE_LAYOUT), (self.detail_size, DETAIL_LAYOUT)):
                tex = gpu.track(gpu.ctx.texture3d((size,) * 3, 4, dtype="f1"))
                made.append(tex)
                tex.repeat_x = tex.repeat_y = tex.repeat_z = True
                tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
                bind_images(program, noise_volume=tex)
                program["size"].value = size
                program["seed"].value = self.seed
                program["texture_index"].value = index
                program["perlin_frequency"].value = perlin
                program["worley_frequency"].value = worley
                groups = math.ceil(size / 4)
                dispatch(program, groups, groups, groups)
            gpu.ctx.finish()
        except Exception:
            for tex in made:
                tex.release()
            raise
        return tuple(made)

    def bind(self, program, time: float, wind, scale: float, strength: float, layer=(0.0, 1.0)) -> None:
        """Bind ``base`` and ``detail`` to ``detail.glsl``'s samplers and write its Detail block
        (where ``program`` has it; written only when it changed): the scroll of ``wind`` (m/s, 3 numbers)
        over ``time`` (s), the base tile ``scale`` (m), the ``strength`` (0..1) and ``layer``, the
        layer's (base y, height) in m (the height gradient)."""
        bind_textures(program, detail_base_noise=self.base, detail_fine_noise=self.detail)
        offset_base, offset_fine = detail_offsets(time, wind, scale)
        strength = float(strength)
        write_block(program, DETAIL_BLOCK, DETAIL_BINDING, _DETAIL_LAYOUT.pack(
            *offset_base, 1.0 / scale, *offset_fine, DETAIL_RATIO / scale,
            float(layer[0]), 1.0 / max(float(layer[1]), 1e-6), strength, BAND_STRENGTH * strength,
            COVERAGE, band_width(strength)))

    def read(self) -> tuple[np.ndarray, np.ndarray]:
        """Both textures as float64 in [0, 1], (n, n, n, 4) indexed [x, y, z, channel] (tests, pictures)."""
        def one(tex):
            n = tex.size[0]
            return np.frombuffer(tex.read(), np.uint8).reshape(n, n, n, 4).transpose(2, 1, 0, 3) / 255.0
        self.gpu.make_current()
        return one(self.base), one(self.detail)
