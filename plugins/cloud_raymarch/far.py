"""The ray march's volumetric far field: the uniforms of ``shaders/cloud_raymarch/far.glsl``.

Beyond the simulated volume the march goes on through the layer's altitude band with the volume's own
column statistics: a point whose far-field fbm (:mod:`atmos.plugins.cloud_far_field`, the graph
resource "far_field": the same octaves and drift as the 2D far field and the ground shadows) has rank
r gets the volume's column sum at rank r (the edge-weighted quantiles ``cover.comp`` measures each
frame) spread over height as the volume's covered columns of that rank are (the profile the same pass
measures: :attr:`atmos.plugins.cloud_far_field.layer.FarFieldLayer.profile`); so it is covered as often,
as thick per cover and at the same heights as the volume. Float64 reference :mod:`.far_reference`. With it on, the 2D far-field pass declares nothing (culled): the march
replaces it (:meth:`atmos.plugins.cloud_far_field.plugin.CloudFarFieldPlugin.drawn_by_march`).
"""
from __future__ import annotations

import numpy as np

from atmos.plugins.cloud_raymarch.noise import pixel_angle

SUN_STEPS = 3                                              # far.glsl's march toward the sun (channels d.yzw)
MAX_SUN_STEP = 2000.0                                      # m: the longest of those steps


def sun_steps(sun_dir, light_step_m: float, height: float) -> tuple[float, float, float]:
    """far.glsl's ``far_sun``: (step toward the sun in m, light-march channels per step, layer height
    fraction per step). A step moves ``light_step_m`` (the channels' spacing) horizontally at most,
    the three cover at most the layer's height vertically, and none is longer than MAX_SUN_STEP."""
    sun = np.asarray(sun_dir, np.float64)
    horizontal, vertical = float(np.hypot(sun[0], sun[2])), float(sun[1])
    ds = MAX_SUN_STEP
    if light_step_m > 0.0 and horizontal > 1e-6:
        ds = min(ds, light_step_m / horizontal)
    if abs(vertical) > 1e-6:
        ds = min(ds, height / (SUN_STEPS * abs(vertical)))
    channels = ds * horizontal / light_step_m if light_step_m > 0.0 else 0.0
    return ds, min(channels, 1.0), ds * vertical / height if height > 0.0 else 0.0    # a layer 0 m thick (floats at 1e30 m)


def far_uniforms(march, far, layout, view, sun_dir, tile_size: float) -> dict:
    """The far field's march uniforms: ``march`` RaymarchCloudSettings, ``far`` CloudFarFieldSettings,
    ``layout`` the march's layer layout, ``view`` the SceneView, ``sun_dir`` unit toward the sun,
    ``tile_size`` the far field's tile as drawn (FarFieldLayer.tile_size)."""
    base, height = float(layout.lo[1]), float(layout.hi[1] - layout.lo[1])
    pixel = pixel_angle(view)
    return {"far_distance": float(march.far_distance), "far_growth": float(march.far_step_growth),
            "far_lod_scale": float(far.size / tile_size * pixel), "far_band": (base, height),
            "far_sun": sun_steps(sun_dir, float(far.light_step * tile_size), height)}
