"""Cloud shadows on the ground (thesis 7.3.1): the top-view density map projected along the light.

``CloudShadowsPlugin`` adds the "cloud_shadows" pass (reads "depth", multiplies "color");
``CloudShadowParams`` its settings; ``CloudLayer`` the world placement of the cloud cells;
``reference`` the numpy float64 shadow factor the GPU is tested against.
"""
from atmos.plugins.cloud_shadows import reference
from atmos.plugins.cloud_shadows.layer import CloudLayer
from atmos.plugins.cloud_shadows.params import CloudShadowParams
from atmos.plugins.cloud_shadows.plugin import CloudShadowsPass, CloudShadowsPlugin

__all__ = ["CloudLayer", "CloudShadowParams", "CloudShadowsPass", "CloudShadowsPlugin", "reference"]
