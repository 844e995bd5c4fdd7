"""The column sums as passes outside the volume read them (``shaders/clouds/volume/column.glsl``: the
optical depth toward the sun above a world point, through mix(A, B, t)'s density maps): the ground
shadows and the light shafts' march both include it."""
from __future__ import annotations

from atmos.gpu.uniforms import bind_textures, write_uniforms
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.volume.sets import CloudSets


def column_uniforms(program, sim: CloudSets, layout: CloudLayout, extinction: float) -> None:
    """Bind mix(A, B, t)'s column sums and set the uniforms of ``clouds/volume/column.glsl``."""
    bind_textures(program, sums_a=sim.maps_of(sim.a).sums, sums_b=sim.maps_of(sim.b).sums)
    write_uniforms(program, extinction=extinction, t=sim.t, a_shift=(sim.a_shift[0], sim.a_shift[2]),
                   layer_min=tuple(map(float, layout.lo)), cell_size=layout.cell, shape=layout.shape,
                   edge_fade=float(sim.settings.edge_fade))
