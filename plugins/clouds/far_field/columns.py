"""The volume's columns as the far field's GPU measures read them (``shaders/clouds/far_field/columns.glsl``,
shared by ``cover.comp`` and ``light_by_rank.comp``): binding the sets' column sums and density with
the uniforms that shader declares, and the small per-rank-interval textures the measures write.
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.clouds.far_field.cover import QUANTILES
from atmos.plugins.clouds.volume.sets import CloudSets
from atmos.gpu.uniforms import bind_textures, write_uniforms

INTERVALS = QUANTILES - 1        # the rank intervals, between the quantiles (columns.glsl INTERVALS)


def use_columns(program, sim: CloudSets, density: bool = True) -> None:
    """Bind mix(A, B, t)'s column sums (and, with ``density``, the density volumes) where columns.glsl
    reads them and set its ``t``, ``a_shift`` and ``edge_fade``."""
    bind_textures(program, sums_a=sim.maps_of(sim.a).sums, sums_b=sim.maps_of(sim.b).sums)
    if density:
        bind_textures(program, density_a=sim.a["density"], density_b=sim.b["density"])
    write_uniforms(program, t=float(sim.t), a_shift=(sim.a_shift[0], sim.a_shift[2]), edge_fade=float(sim.settings.edge_fade))


def rank_texture(gpu, rows: int, components: int):
    """A float32 (INTERVALS, rows) texture of ``components`` channels, clamped (ranks 0 and 1, base and
    top hold the edge texels): what a measure writes per rank interval."""
    texture = gpu.track(gpu.ctx.texture((INTERVALS, rows), components, dtype="f4"))
    texture.repeat_x = texture.repeat_y = False
    return texture


def read_rank_texture(texture) -> np.ndarray:
    """(INTERVALS, rows, components) float64 of a :func:`rank_texture` ([k, row]; a GPU → CPU copy)."""
    w, h = texture.size
    values = np.frombuffer(texture.read(), np.float32).reshape(h, w, texture.components)
    return values.transpose(1, 0, 2).astype(np.float64)
