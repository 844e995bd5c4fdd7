"""Clouds to the horizon: a far field that continues the simulation's cover beyond its volume.

The simulated volume is a few km around the camera; ``CloudSettings.edge_fade`` fades it out toward
its inscribed circle (:mod:`atmos.plugins.clouds.volume.edge`: sprites, ray march and ground shadows), and
:class:`CloudFarFieldPlugin` draws a 2D cloud layer at the volume's middle height with the
complementary weight over the same band, so there is no seam: the sky layer's tileable octaves
(:mod:`atmos.plugins.sky_layer`), each turned and repeating at its own period (:mod:`.pattern`: the sum
repeats nowhere), sized to the volume's clouds and thresholded to the simulation's measured cover (:mod:`.cover`)
and lit by the cloud medium's own light model. References: :mod:`.reference`.
"""
from atmos.plugins.clouds.far_field.settings import CloudFarFieldSettings
from atmos.plugins.clouds.volume.sets import FAR_FIELD
from atmos.plugins.clouds.far_field.plugin import CloudFarFieldPass, CloudFarFieldPlugin

__all__ = ["FAR_FIELD", "CloudFarFieldSettings", "CloudFarFieldPlugin", "CloudFarFieldPass"]
