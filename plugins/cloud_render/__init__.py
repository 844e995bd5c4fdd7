"""Point-sprite cloud rendering of the CloudSimulation with frustum culling and empty-space
skipping (thesis ch. 6, 7.2), and a high-sample ray-marched reference of the same clouds.

``CloudRenderPlugin`` (pass "clouds") draws the sprites; :mod:`.layout` places the volume in the
world; :mod:`.segments` picks and orders the sprite groups; :mod:`.reference` is the numpy
reference of the sprite vertex stage; ``CloudMarchPlugin`` ray-marches the reference image.
"""
from atmos.plugins.cloud_render.frustum import boxes_outside, frustum_planes
from atmos.plugins.clouds.layout import CloudLayout
from atmos.plugins.cloud_render.light import sun_light
from atmos.plugins.cloud_render.plugin import CloudRenderPlugin, CloudRenderSettings, CloudSpritePass
from atmos.plugins.cloud_render.raymarch import CloudMarchPlugin, CloudMarchSettings
from atmos.plugins.cloud_render.segments import SegmentStats, select_segments

__all__ = ["CloudLayout", "CloudMarchPlugin", "CloudMarchSettings", "CloudRenderPlugin", "CloudRenderSettings",
           "CloudSpritePass", "SegmentStats",
           "boxes_outside", "frustum_planes", "select_segments", "sun_light"]
