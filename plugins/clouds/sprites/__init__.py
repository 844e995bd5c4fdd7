"""Point-sprite cloud rendering of the CloudSimulation with frustum culling and empty-space
skipping (thesis ch. 6, 7.2); the reference image of the same clouds is the ray march's
``RaymarchCloudsPlugin.reference()`` (:mod:`atmos.plugins.clouds.raymarch`).

``CloudRenderPlugin`` (pass "cloud_render") draws the sprites; :mod:`.layout` places the volume in the
world; :mod:`.segments` picks and orders the sprite groups; :mod:`.reference` is the numpy
reference of the sprite vertex stage.
"""
from atmos.plugins.clouds.sprites.frustum import boxes_outside, frustum_planes
from atmos.plugins.clouds.volume.layout import CloudLayout
from atmos.plugins.clouds.volume.light import sun_light
from atmos.plugins.clouds.sprites.plugin import CloudRenderPlugin, CloudRenderSettings, CloudSpritePass
from atmos.plugins.clouds.sprites.segments import SegmentStats, select_segments

__all__ = ["CloudLayout", "CloudRenderPlugin", "CloudRenderSettings",
           "CloudSpritePass", "SegmentStats",
           "boxes_outside", "frustum_planes", "select_segments", "sun_light"]
