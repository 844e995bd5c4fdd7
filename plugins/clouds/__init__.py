"""Cloud field smoothing (thesis eq. 2.11, sec. 4.4) and density maps for empty-space skipping (7.2.2).

``Smoother`` turns the automaton's cld bits into a float density volume on the GPU;
``DensityMaps`` sums it into top-view maps (all heights and per height band) and max-downsamples
them to the sprite-group grid; ``reference`` holds the numpy float64 references of both.
"""
from atmos.plugins.clouds import reference
from atmos.plugins.clouds.density_maps import DensityMaps
from atmos.plugins.clouds.smoothing import FORMATS, Smoother, read_volume, slice_range

__all__ = ["DensityMaps", "FORMATS", "Smoother", "read_volume", "reference", "slice_range"]
