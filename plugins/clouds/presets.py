"""Clouds for a game: named skies in metres, and a simulation volume that follows the camera by itself.

``CloudSky("fair_weather")`` is the whole cloud chain as one plugin group: the simulation
(:class:`CloudsPlugin`), its renderer (the ray march or the sprites), a far field to the horizon,
the ground shadows (:class:`CloudShadowsPlugin`), :class:`FollowCameraPlugin`, which keeps the volume centred on
the camera in whole cells (the automaton advects by the move, so clouds stay where they are in
the world), and :class:`CloudWeatherPlugin` (``sky.weather``), which changes the weather while the
game runs: ``sky.weather.configure(preset="overcast", transition=30)`` or ``configure(cover=0.6)``
moves cover, cloud size, darkness, base and thickness there over ``transition`` seconds of game time.
``cloud_settings(preset, cover=..., altitude=..., ...)`` gives the settings alone.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

from atmos.camera import Camera
from atmos.checks import CheckedSettings, check_bool, check_choice, check_num, choice_field, num_field
from atmos.plugin import Plugin, PluginGroup
from atmos.demo_registry import CLOUD_RENDERERS, DEFAULT_CLOUDS
from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.weather.example import example_weather
from atmos.plugins.clouds.shadows import CloudShadowsPlugin
from atmos.plugins.clouds.simulation.plugin import CloudsPlugin
from atmos.plugins.clouds.simulation.chain import CloudSettings
from atmos.plugins.clouds.weather import VolumeOrigin

SHAPE = (128, 16, 128)          # cells of every preset's volume: x, height, z
FULL_COVER = 700                # weather ellipsoids over 128 x 128 columns that close the sky
EDGE_FADE = 0.35                # outer fraction of the volume's half width over which it gives way to the far field


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
    """Keeps the volume of ``clouds`` (a CloudsPlugin of the same App) centred on the Camera (update
    stage, "clouds_follow_camera", after any camera controller of that stage)."""

    def __init__(self, clouds: CloudsPlugin):
        super().__init__()
        if not isinstance(clouds, CloudsPlugin):
            raise ValueError(f"FollowCameraPlugin moves a CloudsPlugin's volume; got {type(clouds).__name__}")
        self.clouds = clouds

    def build(self, app) -> None:
        app.add_system(self.follow, "update", label="clouds_follow_camera")

    def finish(self, app) -> None:
        self.follow(app)                 # centred before the start-up warm-up forms the first clouds

    def follow(self, app) -> None:
        camera, origin = app.get_resource(Camera), app.get_resource(VolumeOrigin)
        if camera is not None and origin is not None:
            origin.x, origin.z = follow_origin(camera.position, self.clouds.settings)


@dataclass(frozen=True)
class CloudWeatherSettings(CheckedSettings):
    """The weather a CloudSky moves toward (all live: a change starts a transition from where the
    weather is now)."""
    preset: str = choice_field("fair_weather", tuple(PRESETS), "the sky's kind: its cover, cloud size, "
                               "darkness (sigma_t), base altitude and thickness")
    cover: float | None = num_field(None, 0.0, 1.0, "the fraction of the sky to cover (None: the preset's)",
                                    optional=True)
    transition: float = num_field(20.0, 0.0, 3600.0, "seconds of game time a change takes (0: at once; the "
                                  "clouds themselves still form and dissolve over a few simulation steps)")


class CloudWeatherPlugin(Plugin):
    """Moves a CloudsPlugin's weather toward :class:`CloudWeatherSettings` over ``transition`` seconds
    (update stage): the cover as the number of weather ellipsoids (added or removed fast enough to get
    there in time), and cloud size, extinction, base altitude and thickness blended with a smoothstep.
    ``configure(preset=..., cover=..., transition=...)`` while playing; :attr:`cover` is where the
    weather is now."""

    settings_class = CloudWeatherSettings

    def __init__(self, settings=None, *, clouds: CloudsPlugin | None = None, **fields):
        super().__init__(settings, **fields)
        if clouds is not None and not isinstance(clouds, CloudsPlugin):
            raise ValueError(f"CloudWeatherPlugin changes a CloudsPlugin's weather (clouds=...); got "
                             f"{type(clouds).__name__}")
        self.clouds = clouds
        self._now = self._target = self._start = self._values(self.settings)
        self._t0 = self._time = self._duration = 0.0
        if clouds is not None:
            self._start_from(clouds.settings)

    def _start_from(self, s) -> None:
        """Where the weather is: the clouds' own settings."""
        cx = s.cell_size[0]
        self._now = {"cover": self._values(self.settings)["cover"], "size": s.weather.cloud_size * cx,
                     "sigma_t": s.sigma_t, "altitude": s.base_altitude,
                     "thickness": s.cell_size[1] * s.weather.volume_shape[1]}
        self._target = dict(self._now)
        self._start, self._t0, self._time, self._duration = self._now, 0.0, 0.0, 0.0

    @staticmethod
    def _values(s: CloudWeatherSettings) -> dict:
        p = PRESETS[s.preset]
        return {"cover": p.cover if s.cover is None else s.cover, "size": p.size, "sigma_t": p.sigma_t,
                "altitude": p.altitude, "thickness": p.thickness}

    @property
    def cover(self) -> float:
        """The cover the weather aims at now (moving toward the settings' during a transition)."""
        return self._now["cover"]

    def configure(self, **changes):
        settings = super().configure(**changes)
        self._start, self._target = dict(self._now), self._values(self.settings)
        self._t0, self._duration = self._time, self.settings.transition
        return settings

    def build(self, app) -> None:
        if self.clouds is None:
            raise ValueError("CloudWeatherPlugin needs the CloudsPlugin it changes: CloudWeatherPlugin(clouds=...) "
                             "(CloudSky makes both)")
        app.add_system(self.update, "update", label="cloud_weather")

    def update(self, app) -> None:
        self._time = app.clock.frame_time
        if self._now == self._target:
            return
        s = 1.0 if self._duration <= 0 else min(max((self._time - self._t0) / self._duration, 0.0), 1.0)
        eased = s * s * (3.0 - 2.0 * s)
        now = {k: self._start[k] + (self._target[k] - self._start[k]) * (s if k == "cover" else eased)
               for k in self._target}
        self._now = self._target if s >= 1.0 else now
        self._apply()

    def _apply(self) -> None:
        v, s = self._now, self.clouds.settings
        cx, _, cz = s.cell_size
        cell_y = v["thickness"] / s.weather.volume_shape[1]
        clouds = max(1, int(math.ceil(v["cover"] * FULL_COVER)))
        goal = max(1, int(math.ceil(self._target["cover"] * FULL_COVER)))
        steps = max(1.0, self._duration / s.step_seconds)          # weather steps left to get there
        adaption = max(4, int(math.ceil(abs(goal - s.weather.cloud_density) / steps)), s.weather.density_adaption)
        self.clouds.configure(sigma_t=v["sigma_t"], base_altitude=v["altitude"], cell_size=(cx, cell_y, cz),
                              weather={"cloud_density": clouds, "density_adaption": adaption,
                                       "cloud_size": v["size"] / cx, "cloud_size_variance": 0.3 * v["size"] / cx})


class CloudSky(PluginGroup):
    """A cloudy sky for a game: ``CloudSky("fair_weather" | "broken" | "overcast", seed=0,
    warmup_steps=12, transition=20, renderer="march", horizon=True, **preset_changes)`` (see
    :func:`cloud_settings`); ``renderer``: "march" (the ray march, :class:`RaymarchCloudsPlugin`) or
    "sprites" (the thesis's point sprites, :class:`CloudRenderPlugin`), the plugin in ``sky.renderer``;
    ``horizon``: a far field continues the clouds to the horizon (:class:`CloudFarFieldPlugin`,
    ``sky.far_field``; the volume fades into it over its outer EDGE_FADE; the march marches it, also
    behind the sprites, ``RaymarchCloudsPlugin(volume=False)``); ``sky.weather``
    (:class:`CloudWeatherPlugin`) changes the sky while playing."""

    def __init__(self, preset: str = "fair_weather", *, seed: int = 0, warmup_steps: int = WARMUP_STEPS,
                 transition: float = 20.0, renderer: str = DEFAULT_CLOUDS, horizon: bool = True, **changes):
        check_choice("CloudSky", "renderer", renderer, CLOUD_RENDERERS)
        horizon = check_bool("CloudSky", "horizon", horizon)
        settings = cloud_settings(preset, **changes)
        if horizon:
            settings = replace(settings, edge_fade=EDGE_FADE)
        clouds = CloudsPlugin(settings, seed=seed, warmup_steps=warmup_steps)
        self.weather = CloudWeatherPlugin(clouds=clouds, preset=preset, cover=changes.get("cover"), transition=transition)
        self.renderer = RaymarchCloudsPlugin() if renderer == "march" else CloudRenderPlugin(size_factor=4.0)
        self.far_field = CloudFarFieldPlugin() if horizon else None
        far = []
        if horizon:
            far.append(self.far_field)
            if renderer == "sprites":
                far.append(RaymarchCloudsPlugin(volume=False))      # the march draws the far field behind them
        super().__init__(clouds, self.renderer, CloudShadowsPlugin(), FollowCameraPlugin(clouds), self.weather, *far)
