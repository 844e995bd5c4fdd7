"""The ray march's volumetric far field: the uniforms of ``shaders/clouds/raymarch/far.glsl``.

Beyond the simulated volume the march goes on through the layer's altitude band with the volume's own
column statistics: a point whose far-field fbm (:mod:`atmos.plugins.clouds.far_field`, the graph
resource "far_field": the same octaves and drift as the 2D far field and the ground shadows) has rank
r gets the volume's column sum at rank r (the edge-weighted quantiles ``cover.comp`` measures each
frame) spread over height as the volume's covered columns of that rank are (the profile the same pass
measures: :attr:`atmos.plugins.clouds.far_field.layer.FarFieldLayer.profile`); so it is covered as often,
as thick per cover and at the same heights as the volume, and lit by the volume's own light at that
rank and height (:mod:`atmos.plugins.clouds.far_field.rank_light`). Float64 reference
:mod:`.far_reference`. With it on, the 2D far-field pass declares nothing (culled): the march
replaces it (:meth:`atmos.plugins.clouds.far_field.plugin.CloudFarFieldPlugin.drawn_by_march`).
"""
from __future__ import annotations

from atmos.plugins.clouds.raymarch.noise import pixel_angle


def far_uniforms(march, far, layout, view, tile_size: float) -> dict:
    """The far field's march uniforms: ``march`` RaymarchCloudSettings, ``far`` CloudFarFieldSettings,
    ``layout`` the march's layer layout, ``view`` the SceneView, ``tile_size`` the far field's tile as
    drawn (FarFieldLayer.tile_size)."""
    base, height = float(layout.lo[1]), float(layout.hi[1] - layout.lo[1])
    pixel = pixel_angle(view)
    return {"far_distance": float(march.far_distance), "far_growth": float(march.far_step_growth),
            "far_lod_scale": float(far.size / tile_size * pixel), "far_band": (base, height)}
