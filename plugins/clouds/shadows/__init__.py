"""Cloud shadows on the ground (thesis 7.3.1): the top-view density map projected along the light.

``CloudShadowsPlugin`` adds the "cloud_shadows" pass (reads "depth", multiplies "color");
``CloudShadowSettings`` its settings; ``cloud_layout`` the volume's world placement (the sprite
renderer's :class:`~atmos.plugins.clouds.volume.layout.CloudLayout`);
``reference`` the numpy float64 shadow factor the GPU is tested against.
"""
from atmos.plugins.clouds.shadows import reference
from atmos.plugins.clouds.shadows.settings import CloudShadowSettings
from atmos.plugins.clouds.shadows.plugin import CloudShadowsPass, CloudShadowsPlugin, cloud_layout

__all__ = ["CloudShadowSettings", "CloudShadowsPass", "CloudShadowsPlugin", "cloud_layout", "reference"]
