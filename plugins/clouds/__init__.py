"""The cloud family under one roof. Sub-packages, from the simulation to the pictures:

``weather`` (ellipsoids → region volume) → ``automaton`` (Dobashi's cellular automaton) →
``simulation`` (``CloudsPlugin``: the chain as a sliced job into three texture sets, smoothing,
density maps) → ``light`` (shading toward the sun, the diffusion field, the light model and the
path tracer) → ``volume`` (what every renderer shares: the sets and layout it publishes, the light
binding, the off-screen clouds) → the renderers ``raymarch`` and ``sprites``, the ``far_field`` to
the horizon and the ground ``shadows``; ``presets`` (``CloudSky``) puts them together for a game.
"""
from atmos.plugins.clouds.simulation import reference
from atmos.plugins.clouds.simulation.chain import CloudSettings, CloudSimulation
from atmos.plugins.clouds.simulation.density_maps import DensityMaps
from atmos.plugins.clouds.simulation.plugin import CloudsPlugin
from atmos.plugins.clouds.simulation.smoothing import FORMATS, Smoother, read_volume, slice_range
from atmos.plugins.clouds.volume.column import column_uniforms
from atmos.plugins.clouds.volume.sets import CLOUD_SETS, FAR_FIELD, CloudSets

__all__ = ["CLOUD_SETS", "FAR_FIELD", "CloudSets", "CloudSettings", "CloudSimulation", "CloudSky", "CloudTopViewPlugin", "CloudsPlugin",
           "DensityMaps", "FORMATS", "Smoother", "column_uniforms", "read_volume", "reference", "slice_range"]

_LAZY = {"CloudSky": "atmos.plugins.clouds.presets", "CloudTopViewPlugin": "atmos.plugins.clouds.simulation.top_view"}


def __getattr__(name: str):
    """The presets and the top view on first use (they bring the renderers: a pass that only reads the
    published sets does not need them)."""
    if name not in _LAZY:
        raise AttributeError(f"module 'atmos.plugins.clouds' has no attribute {name!r}")
    from importlib import import_module
    value = globals()[name] = getattr(import_module(_LAZY[name]), name)
    return value
