"""An animated test volume that exercises the whole stack.

Each simulation step fills a 3D density texture with drifting, pulsing blobs; the fill is split into
slices handed out by the frame scheduler into the C set of a triple-buffered texture set, while the
ray-march pass draws A and B interpolated by C's progress. It is the template an expensive effect
follows (the cloud simulation does the same with its stage chain).
"""
from atmos.plugins.test_volume.plugin import TestVolumePlugin, TestVolumeSettings, VolumeBox

__all__ = ["TestVolumePlugin", "TestVolumeSettings", "VolumeBox"]
