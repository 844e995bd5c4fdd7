"""The volumetric fog's noise: the value-noise lattice of ``lib/value_noise.glsl`` repeating every ``LATTICE``
cells per axis (``volumetric_fog/lattice.glsl``), either baked once per seed into a 3D texture
(``volumetric_fog/lattice.comp``) and read with one filtered fetch per octave (``noise="filtered"``), or
its 8 corners hashed per octave (``"hash"``: 24 integer hashes). float64 twin:
``atmos.value_noise.fbm(..., period=LATTICE)``."""
from __future__ import annotations

import math

import numpy as np

from atmos.gpu.context import require_gpu
from atmos.gpu.hazards import dispatch
from atmos.gpu.host_memory import is_software
from atmos.gpu.uniforms import bind_images, write_uniforms

LATTICE = 64                 # cells per axis before the lattice repeats (a power of two): 1 MiB of r32f
FILTER_FRACTION_BITS = 8     # the fewest fraction bits a texture unit blends with (NVIDIA: 8; Mesa: more)


def noise_kind(settings, gpu) -> str:
    """"filtered" or "hash": ``settings.noise``, "auto" being the filtered fetch on a GPU and the hash on a
    software renderer (which emulates texture units: there the hash is the cheaper of the two)."""
    if settings.noise != "auto":
        return settings.noise
    software = gpu.__dict__.get("_software")
    if software is None:
        software = gpu.__dict__["_software"] = is_software(gpu.ctx)
    return "hash" if software else "filtered"


def noise_defines(settings, gpu) -> dict:
    """The defines of ``volumetric_fog/lattice.glsl`` for ``settings`` on ``gpu``."""
    return {"FOG_LATTICE": LATTICE, "FOG_NOISE_FILTERED": int(noise_kind(settings, gpu) == "filtered")}


def filtered_error(octaves: int) -> float:
    """The most a filtered fetch adds to the FBM's error: per octave of amplitude a, at most
    3 · 2^-bits · a (each axis's weight off by one step of the texture unit's fraction, lattice values
    within [0, 1)), summed over the octaves."""
    return 3.0 * 2.0 ** -FILTER_FRACTION_BITS * (1.0 - 2.0 ** -min(int(octaves), 16))


class Lattice:
    """The (LATTICE³) r32f lattice texture of one seed, repeat-wrapped and linearly filtered (the
    filtered noise's); ``sync`` bakes it again when the seed changes."""

    def __init__(self, gpu):
        self.gpu = require_gpu(gpu)
        self.texture = None
        self.seed = None

    def sync(self, seed: int):
        """The texture of ``seed`` (baked now if it is another seed than the last)."""
        if self.texture is not None and self.seed == seed:
            return self.texture
        ctx = self.gpu.ctx
        if self.texture is None:
            self.texture = ctx.texture3d((LATTICE,) * 3, 1, dtype="f4")
            self.texture.repeat_x = self.texture.repeat_y = self.texture.repeat_z = True
            self.texture.filter = (ctx.LINEAR, ctx.LINEAR)
        shader = self.gpu.program(compute_shader="volumetric_fog/lattice.comp")
        bind_images(shader, lattice=self.texture)
        write_uniforms(shader, seed=int(seed))
        groups = math.ceil(LATTICE / 4)
        dispatch(shader, groups, groups, groups)
        self.seed = seed
        return self.texture

    def read(self) -> np.ndarray:
        """The lattice as float32 [x, y, z] (for tests)."""
        return np.frombuffer(self.texture.read(), np.float32).reshape((LATTICE,) * 3).transpose(2, 1, 0).copy()

    def release(self) -> None:
        if self.texture is not None:
            self.texture.release()
        self.texture = self.seed = None
