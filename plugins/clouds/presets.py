"""Clouds for a game: named skies in metres, and a simulation volume that follows the camera by itself.

``CloudSky("fair_weather")`` is the whole cloud chain as one plugin group: the simulation
(:class:`CloudsPlugin`), its sprites (:class:`CloudRenderPlugin`), their ground shadows
(:class:`CloudShadowsPlugin`) and :class:`FollowCameraPlugin`, which keeps the volume centred on
the camera in whole cells (the automaton advects by the move, so clouds stay where they are in
the world). ``cloud_settings(preset, cover=..., altitude=..., ...)`` gives the settings alone.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from atmos.camera import Camera
from atmos.checks import check_choice, check_num
from atmos.plugin import Plugin, PluginGroup
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.weather.example import example_weather
from atmos.plugins.clouds.shadows import CloudShadowsPlugin
from atmos.plugins.clouds.simulation.plugin import CloudsPlugin
from atmos.plugins.clouds.simulation.chain import CloudSettings
from atmos.plugins.clouds.weather import VolumeOrigin

SHAPE = (128, 16, 128)          # cells of every preset's volume: x, height, z
FULL_COVER = 700                # weather ellipsoids over 128 x 128 columns that close the sky


@dataclass(frozen=True)
class CloudPreset:
    """``cover``: fraction of the sky the clouds aim to cover (0..1); ``altitude``: cloud base (m);
    ``thickness``: the layer's depth (m); ``extent``: the simulated square's side (m), centred on the
    camera; ``size``: a typical cloud's radius (m); ``sigma_t``: extinction per metre at density 1
    (thicker looks darker)."""
    cover: float
    altitude: float
    thickness: float
    extent: float
    size: float
    sigma_t: float


PRESETS = {
    "fair_weather": CloudPreset(cover=0.15, altitude=900.0, thickness=640.0, extent=5120.0, size=300.0, sigma_t=0.02),
    "broken": CloudPreset(cover=0.45, altitude=1000.0, thickness=800.0, extent=5120.0, size=420.0, sigma_t=0.025),
    "overcast": CloudPreset(cover=1.0, altitude=700.0, thickness=900.0, extent=5120.0, size=600.0, sigma_t=0.04),
}
WARMUP_STEPS = 12


def cloud_settings(preset: str = "fair_weather", **changes) -> CloudSettings:
    """The CloudSettings of ``preset`` (one of PRESETS), with any :class:`CloudPreset` field changed
    (``cover=0.3``, ``altitude=1500``...; each checked, naming it)."""
    base = PRESETS[check_choice("cloud_settings", "preset", preset, tuple(PRESETS))]
    unknown = set(changes) - set(CloudPreset.__dataclass_fields__)
    if unknown:
        raise ValueError(f"cloud_settings has no field {', '.join(sorted(unknown))}; allowed: "
                         f"{', '.join(CloudPreset.__dataclass_fields__)}")
    p = replace(base, **changes)
    o = "cloud_settings"
    cover = check_num(o, "cover", p.cover, 0.0, 1.0)
    altitude = check_num(o, "altitude", p.altitude, -1e5, 1e5)
    thickness = check_num(o, "thickness", p.thickness, 16.0, 2e4)
    extent = check_num(o, "extent", p.extent, 128.0, 1e6)
    size = check_num(o, "size", p.size, 1.0, 1e5)
    sigma_t = check_num(o, "sigma_t", p.sigma_t, 0.0, 10.0, lo_open=True)
    cell = (extent / SHAPE[0], thickness / SHAPE[1], extent / SHAPE[2])
    clouds = max(1, int(math.ceil(cover * FULL_COVER)))
    weather = example_weather(SHAPE, cloud_density=clouds, cloud_size=size / cell[0], cloud_size_variance=0.3 * size / cell[0],
                              density_adaption=max(4, math.ceil(clouds / WARMUP_STEPS)))   # formed by the warm-up
    return CloudSettings(weather=weather, cell_size=cell, base_altitude=altitude, smoothing_slices=8,
                         group_size=(32, 32), sigma_t=sigma_t)


def follow_origin(camera_position, settings: CloudSettings) -> tuple[float, float]:
    """The VolumeOrigin (x, z, in whole cells) that centres the volume on ``camera_position``."""
    shape, cell = settings.weather.volume_shape, settings.cell_size
    return (float(math.floor(camera_position[0] / cell[0] - shape[0] / 2)),
            float(math.floor(camera_position[2] / cell[2] - shape[2] / 2)))


class FollowCameraPlugin(Plugin):
    """Keeps the cloud volume centred on the Camera (update stage, "clouds_follow_camera", after any
    camera controller of that stage); needs a CloudsPlugin."""

    def build(self, app) -> None:
        app.add_system(self.follow, "update", label="clouds_follow_camera")

    def finish(self, app) -> None:
        if not any(isinstance(p, CloudsPlugin) for p in app.plugins):
            raise ValueError("FollowCameraPlugin moves the cloud volume, but the App has no CloudsPlugin")
        self.follow(app)                 # centred before the start-up warm-up forms the first clouds

    def follow(self, app) -> None:
        clouds = next(p for p in app.plugins if isinstance(p, CloudsPlugin))
        camera, origin = app.get_resource(Camera), app.get_resource(VolumeOrigin)
        if camera is not None and origin is not None:
            origin.x, origin.z = follow_origin(camera.position, clouds.settings)


class CloudSky(PluginGroup):
    """A cloudy sky for a game: ``CloudSky("fair_weather" | "broken" | "overcast", seed=0,
    warmup_steps=12, **preset_changes)`` (see :func:`cloud_settings`)."""

    def __init__(self, preset: str = "fair_weather", *, seed: int = 0, warmup_steps: int = WARMUP_STEPS, **changes):
        settings = cloud_settings(preset, **changes)
        super().__init__(CloudsPlugin(settings, seed=seed, warmup_steps=warmup_steps),
                         CloudRenderPlugin(size_factor=4.0), CloudShadowsPlugin(), FollowCameraPlugin())
