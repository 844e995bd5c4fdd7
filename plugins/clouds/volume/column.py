"""The column sums as passes outside the volume read them (``shaders/clouds/volume/column.glsl``: the
optical depth toward the sun above a world point, through mix(A, B, t)'s density maps): the ground
shadows and the light shafts' march both include it."""
from __future__ import annotations

from atmos.gpu.uniforms import bind_textures, write_uniforms
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.volume.sets import CloudSets
from atmos.plugins.clouds.volume.shape import centre_rise, shape_uniforms


UNTYPED = shape_uniforms(None, None)      # shape.glsl's uniforms where no type is drawn (worked out once)


def column_uniforms(program, sim: CloudSets, layout: CloudLayout, extinction: float) -> None:
    """Bind mix(A, B, t)'s column sums and set the uniforms of ``clouds/volume/column.glsl``, with the
    cloud type the clouds are drawn with (``sim.drawn``, :class:`.shape.DrawnShape`), or none."""
    bind_textures(program, sums_a=sim.maps_of(sim.a).sums, sums_b=sim.maps_of(sim.b).sums)
    write_uniforms(program, extinction=extinction, t=sim.t, a_shift=(sim.a_shift[0], sim.a_shift[2]),
                   layer_min=tuple(map(float, layout.lo)), cell_size=layout.cell, shape=layout.shape,
                   edge_fade=float(sim.settings.edge_fade))
    drawn = sim.drawn.current() if sim.drawn is not None else None
    if drawn is None:
        write_uniforms(program, UNTYPED, type_rise=0.0)
        return
    cloud_type, type_map, texture = drawn
    write_uniforms(program, shape_uniforms(cloud_type, type_map), type_rise=centre_rise(cloud_type, type_map))
    bind_textures(program, typed_columns=sim.drawn.columns(program.ctx))
    if texture is not None:
        bind_textures(program, cloud_type_map=texture)


def drawn_types(sim) -> dict:
    """``cloud_type`` and ``type_map`` of the shape ``sim`` (CloudSets) is drawn with, for the float64
    twins' keywords (both None: the simulation's own shape)."""
    drawn = sim.drawn.current() if getattr(sim, "drawn", None) is not None else None
    return {"cloud_type": None, "type_map": None} if drawn is None else {"cloud_type": drawn[0], "type_map": drawn[1]}
