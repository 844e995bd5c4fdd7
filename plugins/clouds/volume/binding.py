"""Binding the simulation's A/B textures and the light model to a program (``clouds/volume/volume.glsl``)."""
from __future__ import annotations

from atmos.lighting import Sun
from atmos.plugins.clouds.volume.light import DEFAULT_OCTAVES, light_uniforms
from atmos.plugins.clouds.volume.sets import CloudSets
from atmos.plugins.clouds.light.columns import COLUMNS
from atmos.plugins.clouds.light.diffusion import DIFFUSION
from atmos.gpu.uniforms import write_uniforms

UNITS = (0, 1, 2, 3, 10, 11, 16, 17)   # density, transmittance, columns, diffusion field (each a, b)


def bind_volume(program, sim, sampler, sun: Sun | None, octaves=DEFAULT_OCTAVES, diffusion: float = 0.0,
                layer=None) -> float:
    """Bind mix(A, B, t)'s textures (``sim``: the frame's CloudSets, or the CloudSimulation) to units
    0..3 (density, transmittance) and 10, 11 (the light volume's columns) with ``sampler`` and set ``t``, ``a_shift`` (A drawn where it was computed), ``has_shading``
    and the light (:func:`light_uniforms` of the simulation's medium, the sun and the
    multiple-scattering ``octaves``), and 16, 17 (the diffusion field, weight ``diffusion``; 0 where the
    sets have no field; the sun's colour taken over ``layer``, (base, top) world y); returns t. Call
    :func:`unbind_volume` when the draw is done."""
    a, b, t = sim.view()
    shading = "transmittance" in a
    a["density"].use(0)
    b["density"].use(1)
    light = "transmittance" if shading else "density"      # without shading: a placeholder, unread
    a[light].use(2)
    b[light].use(3)
    a[COLUMNS].use(10)
    b[COLUMNS].use(11)
    field = DIFFUSION in a and DIFFUSION in b
    a[DIFFUSION if field else COLUMNS].use(16)         # without a field: a placeholder, unread
    b[DIFFUSION if field else COLUMNS].use(17)
    for unit in UNITS:
        sampler.use(unit)
    program["t"].value = float(t)
    write_uniforms(program, light_uniforms(sim.settings, sun, octaves, diffusion if field else 0.0, layer),
                   a_shift=(sim if isinstance(sim, CloudSets) else sim.sets()).a_shift, has_shading=int(shading),
                   edge_fade=float(sim.settings.edge_fade))
    return float(t)


def unbind_volume(sampler) -> None:
    """Unbind the sampler from the volume's units so later passes sample with their textures' own settings."""
    for unit in UNITS:
        sampler.clear(unit)
