"""Binding the simulation's A/B textures and the light model to a program (``clouds/volume/volume.glsl``)."""
from __future__ import annotations

import moderngl

from atmos.lighting import Sun
from atmos.plugins.clouds.volume.light import DEFAULT_OCTAVES, light_uniforms, write_light
from atmos.plugins.clouds.volume.sets import CloudSets
from atmos.plugins.clouds.light.columns import COLUMNS
from atmos.plugins.clouds.light.diffusion import DIFFUSION
from atmos.plugins.clouds.light.ground import bind_ground
from atmos.gpu.uniforms import bind_textures, sampler_units

SAMPLERS = ("density_a", "density_b", "trans_a", "trans_b", "columns_a", "columns_b", "diffusion_a", "diffusion_b")


def bind_volume(program, sim, sampler, sun: Sun | None, octaves=DEFAULT_OCTAVES, diffusion: float = 0.0,
                layer=None, ground=None, *, ground_light, span: float = 1.0) -> float:
    """Bind mix(A, B, t)'s textures (``sim``: the frame's CloudSets, or the CloudSimulation) to
    ``volume.glsl``'s samplers (density, transmittance, the light volume's columns, the diffusion field)
    with ``sampler`` and set ``t``, ``a_shift`` (A drawn where it was computed), ``has_shading`` and the
    light (:func:`light_uniforms` of the simulation's medium, the sun and the multiple-scattering
    ``octaves``; the diffusion field's weight ``diffusion``, 0 where the sets have no field; the sun's
    colour taken over ``layer``, (base, top) world y, and ``span`` times its height for a cloud type's
    towers; the ground below of the scene's ``ground``, a
    GroundSurface (None: the medium's albedo), in the clouds' shadow ``ground_light``, the frame's
    "cloud_ground" buffer (:mod:`atmos.plugins.clouds.light.ground`)); returns t. Call :func:`unbind_volume` when the
    draw is done."""
    a, b, t = sim.view()
    ta, tb = a.textures, b.textures                        # the sets' own dicts (their names are checked below)
    shading = "transmittance" in ta
    light = "transmittance" if shading else "density"      # without shading: a placeholder, unread
    field = DIFFUSION in ta and DIFFUSION in tb
    spread = DIFFUSION if field else COLUMNS               # without a field: a placeholder, unread
    try:
        textures = dict(density_a=ta["density"], density_b=tb["density"], trans_a=ta[light], trans_b=tb[light],
                        columns_a=ta[COLUMNS], columns_b=tb[COLUMNS], diffusion_a=ta[spread], diffusion_b=tb[spread])
    except KeyError:
        for s in (a, b):
            s["density"], s[light], s[COLUMNS]             # the error that names what the set lacks
        raise
    bind_textures(program, textures, sampler=sampler)
    bind_ground(program, ground_light)
    write_light(program, light_uniforms(sim.settings, sun, octaves, diffusion if field else 0.0, layer,
                                        None if ground is None else ground.albedo, span),
                   a_shift=(sim if isinstance(sim, CloudSets) else sim.sets()).a_shift, has_shading=int(shading),
                   edge_fade=float(sim.settings.edge_fade), t=float(t))
    return float(t)


def unbind_volume(program, sampler) -> None:
    """Unbind the sampler from the volume's units so later passes sample with their textures' own settings
    (the units looked up once per program; moderngl's Sampler.clear made on its C object)."""
    extra = program.extra
    units = extra.get("volume_units") if type(extra) is dict else None
    if units is None:
        units = [unit for unit in (sampler_units(program, name) for name in SAMPLERS) if unit is not None]
        if type(extra) is dict:
            extra["volume_units"] = units
    clear = sampler.mglo.clear if type(sampler) is moderngl.Sampler else sampler.clear
    for unit in units:
        clear(unit)
