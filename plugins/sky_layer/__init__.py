"""The 2D dynamic cloud layer (dynamic-2d-clouds-iq.txt): four seamlessly tiling noise octaves (4D noise
on two circles) scrolling at different speeds, fbm weights 1/2..1/16, emptiness/sharpness remap, four
light-march samples toward the sun packed in RGBA. A scene without :class:`SkyLayerPlugin` runs none of it.
"""
from atmos.plugins.sky_layer.settings import SkyLayerSettings
from atmos.plugins.sky_layer.plugin import SkyLayerPass, SkyLayerPlugin

__all__ = ["SkyLayerSettings", "SkyLayerPlugin", "SkyLayerPass"]
