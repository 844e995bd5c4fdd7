"""The cloud simulation: weather → region volume → automaton → smoothing → density maps.

``CloudsPlugin`` adds the whole chain to an App as a sliced job (``CloudSimulation``);
``Smoother`` turns the automaton's cld bits into a float density volume on the GPU (eq. 2.11,
sec. 4.4); ``DensityMaps`` sums it into top-view maps (all heights and per height band) and
max-downsamples them to the sprite-group grid (7.2.2); ``reference`` holds the numpy float64
references of smoothing and density maps.
"""
from atmos.plugins.clouds import reference
from atmos.plugins.clouds.density_maps import DensityMaps
from atmos.plugins.clouds.plugin import CloudsPlugin
from atmos.plugins.clouds.sets import CLOUD_SETS, CloudSets
from atmos.plugins.clouds.simulation import CloudSettings, CloudSimulation
from atmos.plugins.clouds.smoothing import FORMATS, Smoother, read_volume, slice_range

__all__ = ["CLOUD_SETS", "CloudSets", "CloudSettings", "CloudSimulation", "CloudsPlugin", "DensityMaps", "FORMATS", "Smoother",
           "read_volume", "reference", "slice_range"]
