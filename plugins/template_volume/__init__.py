"""An animated template volume that exercises the whole stack (the testbed demo draws it).

Each simulation step fills a 3D density texture with drifting, pulsing blobs; the fill is split into
slices handed out by the frame scheduler into the C set of a triple-buffered texture set, while the
ray-march pass draws A and B interpolated by C's progress. It is the template an expensive effect
follows (the cloud simulation does the same with its stage chain).
"""
from atmos.plugins.template_volume.plugin import TemplateVolumePlugin, TemplateVolumeSettings, VolumeBox

__all__ = ["TemplateVolumePlugin", "TemplateVolumeSettings", "VolumeBox"]
