"""Live settings: every documented live setting of every plugin takes effect on the next frame.

The cases are generated from the settings dataclasses' fields: each plugin has a small headless
scene (64×40) and, per live field (every field not in ``FIXED``), a new value; the test renders a
frame, checks that an unchanged frame renders the same (the scenes are frozen: dt = 0, sliced jobs
paused), ``configure``s the one field, renders one frame and asserts the frame's pixels (HDR colour
and the screen) changed — or, for settings with no visible effect in that scene, the observable they
drive (a texture size in the compiled graph, culling counters, the clock). A coverage test fails
when a settings class gains a live field without a case here. Rejected changes (bad value, unknown
name, a fixed field) raise a ValueError naming ``Class.field`` and leave the settings object, the
plugin and the rendered pixels as they were.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import pytest

from atmos.app import App
from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.gpu import create_headless
from atmos.lighting import Sun
from atmos.plugin import Plugin
import atmos.plugins.clouds.simulation.chain as cloud_simulation
import atmos.plugins.clouds.weather.system as weather_system
from atmos.checks import CheckedSettings
from atmos.plugins.clouds.raymarch import RaymarchCloudsPlugin
from atmos.plugins.clouds.raymarch.plugin import LOW_COLOR as RAYMARCH_LOW_COLOR
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.weather.example import example_weather
from atmos.offscreen import CLOUD_COLOR
from atmos.plugins.clouds.shadows import CloudShadowsPlugin
from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.clouds.presets import CloudSky, CloudWeatherPlugin
from atmos.plugins.antialias import AntialiasPlugin
from atmos.plugins.mesh import MeshPlugin
from atmos.plugins.clouds.volume.shape import CloudTypeMap
from atmos.plugins.physical_camera import PhysicalCameraPlugin
from atmos.plugins.clouds.simulation.top_view import CloudTopViewPlugin
from atmos.plugins.daylight import DaylightPlugin, TimeOfDay
from atmos.plugins.fog import FogPlugin
from atmos.plugins.ground import GroundPlugin
from atmos.plugins.light_shafts import LightShaftsPlugin
from atmos.plugins.light_shafts.plugin import MASK
from atmos.overlay import OverlayPlugin
from atmos.plugins.sky import SkyPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.sky_layer import SkyLayerPlugin
from atmos.plugins.terrain import TerrainPlugin
from atmos.plugins.template_volume import TemplateVolumePlugin
from atmos.plugins.volumetric_fog import VolumetricFogPlugin
from atmos.plugins.clouds.weather import WeatherPlugin
from atmos.plugins.clouds.light.scattering import Scattering
from atmos.plugins.clouds.light.shear_warp import ShadingTask
from atmos.render_core import MOTION, CapturePass, RenderCorePlugin

SIZE = (64, 40)
DAY = Sun.from_angles(30.0, 200.0)
NIGHT = Sun.from_angles(-30.0, 200.0, color=(0.0, 0.0, 0.0))


@pytest.fixture(scope="module")
def small_gpu():
    context = create_headless(SIZE)
    yield context
    context.release()


# -- observables ------------------------------------------------------------------------------------
def pixels(app, plugin):
    """What the frame shows: the HDR colour (CapturePass) and the tone-mapped screen."""
    capture = next(p for p in app.graph.passes if isinstance(p, CapturePass))
    return capture.color.copy(), app.gpu.read_pixels()


def resource_size(name):
    def observe(app, plugin):
        compiled = app.graph.compile()
        return compiled.resources[name].desc.size if name in compiled.resources else None
    return observe


def culling_counters(app, plugin):
    s = plugin.stats
    return s.columns_frustum_culled, s.segments_frustum_culled, s.columns_empty, s.segments_empty, s.sprites


def splatted(app, plugin):
    """The sprites the compute splat recorded in the last frame (0 while the points draw them: the same image)."""
    splat = plugin.sprite_pass.splat
    return 0 if splat is None else splat.work()["sprites"]


STEPS: list = []        # (settings, dt) of every weather step, newest last (the scenes' step_weather records)


def recording(step_weather):
    def step(world, settings, rng, dt=1.0, origin=(0.0, 0.0, 0.0)):
        STEPS.append((settings, dt))
        return step_weather(world, settings, rng, dt, origin)
    return step


def next_step_reads(name):
    """What the next simulation step reads: run it (a sliced job's whole step, or the App's own fixed
    step) and return the field its weather rules got (``dt``: the step time)."""
    def observe(app, plugin):
        if isinstance(plugin, CloudsPlugin):
            plugin.simulation.job.run_step()
        settings, dt = STEPS[-1]
        return dt if name == "dt" else getattr(settings, name)
    return observe


def light_channels(app, plugin):
    """The far field's baked light-march channels (the ray march's far field marches the sun through
    them; the 2D layer takes the volume's light by rank instead)."""
    return np.asarray(plugin.layer.octaves.download(0), np.float64)[..., 1:]


def shading_extinction(app, plugin):
    """The extinction the next step's shading task latches."""
    task = next(s for s in plugin.simulation.job.tasks if isinstance(s, ShadingTask))
    return task.sigma()


def same(a, b) -> bool:
    if isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b):
        return all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(a, b)
    return a == b


def live_fields(plugin_or_class, nested: bool = False) -> list[str]:
    """The settings class's fields not in FIXED; ``nested``: a field holding settings of their own
    is listed as its live fields, ``outer.inner``."""
    cls = getattr(plugin_or_class, "settings_class", plugin_or_class)
    names = []
    for f in dataclasses.fields(cls):
        if f.name in cls.FIXED:
            continue
        inner = f.default if isinstance(f.default, CheckedSettings) else None
        if nested and inner is not None and dataclasses.fields(inner):
            names += [f"{f.name}.{sub}" for sub in live_fields(type(inner), nested=True)]
        else:
            names.append(f.name)
    return names


def nested_change(setting, value) -> dict:
    """``configure`` keywords for ``setting`` (``outer.inner``: a dict of changes to the nested settings)."""
    outer, _, inner = setting.partition(".")
    return {outer: {inner: value}} if inner else {outer: value}


def nested_value(settings, setting):
    for name in setting.split("."):
        settings = getattr(settings, name)
    return settings


# -- scenes -----------------------------------------------------------------------------------------
def look(position, target=None, yaw=None, pitch=None, far=None):
    def place(app):
        cam = app.resource(Camera)
        cam.position = np.array(position, float)
        if target is not None:
            cam.look_at(target)
        if yaw is not None:
            cam.yaw, cam.pitch = yaw, pitch
        if far is not None:
            cam.far = far
    return place


def sun_toward(cam: Camera, uv) -> np.ndarray:
    """The direction toward a sun seen at screen ``uv`` (outside [0, 1]: off screen)."""
    ndc = np.array([2 * uv[0] - 1, 2 * uv[1] - 1, 1.0, 1.0])
    far = np.linalg.inv(cam.view_projection(SIZE[0] / SIZE[1])) @ ndc
    d = far[:3] / far[3] - cam.position
    return d / np.linalg.norm(d)


def set_sun(sun: Sun):
    def hook(app, plugin):
        app.insert_resource(Sun(np.array(sun.direction), sun.color))
    return hook


def sun_at(uv, color=(1.0, 0.95, 0.85)):
    def hook(app, plugin):
        app.insert_resource(Sun(sun_toward(app.resource(Camera), uv), color))
    return hook


def freeze_frame_times(app, plugin):
    """The bars show wall-clock frame times: hold them still."""
    plugin.times.record = lambda: None


def physical_ground(height: float | None = None, **changes):
    """The physical sky (and ``changes``), the camera turned down onto the ground: the aerial perspective's view
    (``height``: the camera raised to it, m, so a ray crosses the air's fall with height)."""
    def hook(app, plugin):
        plugin.configure(model="physical", **changes)
        cam = app.resource(Camera)
        cam.pitch = -0.12
        if height is not None:
            cam.position = np.array([cam.position[0], height, cam.position[2]])
    return hook


def configure_first(**changes):
    def hook(app, plugin):
        plugin.configure(**changes)
    return hook


def clouds(shape=(32, 8, 32), cell=(20.0, 15.0, 20.0), cover=40, **settings):
    weather = example_weather(shape, cover)
    base = dict(smoothing_slices=2, group_size=(8, 8), cell_size=cell, base_altitude=300.0)
    base.update(settings)
    return CloudsPlugin(CloudSettings(weather=weather, **base), seed=3, warmup_steps=12)


CLOUD_CENTER = (320.0, 360.0, 320.0)


def march_under_clouds(app, plugin):
    """Marched shafts seen from under the clouds of :func:`clouds`, toward a sun behind them; each frame
    alone (froxel_history 1: the history's jitter moves a still frame; it has its own case)."""
    plugin.configure(mode="march", froxel_history=1.0)
    look((320.0, 40.0, 900.0), target=(320.0, 250.0, 300.0), far=6000.0)(app)
    app.insert_resource(Sun(np.array([0.0, 0.6, -1.0]) / math.hypot(0.6, 1.0), (1.0, 0.95, 0.85)))


def march_per_texel(app, plugin):
    """:func:`march_under_clouds` marched per texel (no froxel volume: ``steps`` counts)."""
    march_under_clouds(app, plugin)
    plugin.configure(froxels=None)


@dataclass
class Spec:
    """A plugin's scene and, per live field, the new value (``changes``); ``observe``: fields whose
    effect is checked on something else than the pixels; ``before``: what a field's case does
    before the first frame (e.g. put the sun where the setting matters); ``frame_dt``: the frame
    time of a field's frames (0 elsewhere: a frozen scene)."""
    make: Callable[[], list]
    kind: type
    camera: Callable
    changes: dict
    sun: Sun = field(default_factory=lambda: DAY)
    observe: dict = field(default_factory=dict)
    before: dict = field(default_factory=dict)
    frame_dt: dict = field(default_factory=dict)
    warm: float = 0.5                  # seconds of clock run before the scene is frozen (animation time > 0)


# the physical sky's atmosphere (SkySettings.model = "physical"), field by field
PHYSICAL_CHANGES = {
    "atmosphere.planet_radius": 2000e3, "atmosphere.atmosphere_height": 30e3,
    "atmosphere.rayleigh_scattering": (20e-6, 10e-6, 5e-6), "atmosphere.rayleigh_scale_height": 3000.0,
    "atmosphere.mie_scattering": (4e-5, 4e-5, 4e-5), "atmosphere.mie_absorption": (4e-5, 4e-5, 4e-5),
    "atmosphere.mie_scale_height": 5000.0, "atmosphere.mie_g": 0.2, "atmosphere.ozone_absorption": (5e-6, 1e-6, 1e-5),
    "atmosphere.ozone_altitude": 5000.0, "atmosphere.ozone_width": 8000.0, "atmosphere.ground_albedo": (1.0, 1.0, 1.0),
    "atmosphere.sun_color": (1.0, 0.5, 0.2), "atmosphere.sun_intensity": 3.0, "atmosphere.multiple_scattering": 0.0}

SPECS = {
    "render_core": Spec(
        lambda: [DefaultPlugins(overlay=False), GroundPlugin()], RenderCorePlugin,
        look((0.0, 3.0, 10.0), yaw=0.0, pitch=0.0),
        dict(clear_color=(0.5, 0.2, 0.1), exposure=3.0, dither=False)),
    "overlay": Spec(
        lambda: [DefaultPlugins(overlay=True), GroundPlugin()], OverlayPlugin,
        look((0.0, 3.0, 10.0), yaw=0.0, pitch=0.0),
        dict(visible=False, size=(20, 10)),
        before={"__all__": freeze_frame_times}),
    "ground": Spec(
        lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin()], GroundPlugin,
        look((0.0, 3.0, 10.0), yaw=0.0, pitch=-0.2),
        dict(half_size=5.0, tile=1.0, albedo=(0.9, 0.1, 0.1), haze_distance=2.0)),
    "sky_gradient": Spec(                                   # the default sun in view, as the sky's
        lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin()], SkyGradientPlugin,
        look((0.0, 2.0, 0.0), yaw=math.radians(200.0), pitch=0.45),
        dict(zenith=(0.9, 0.1, 0.1), horizon=(0.1, 0.9, 0.1), ground=(0.1, 0.1, 0.9), sun_size_deg=4.0, sun_gain=200.0,
             sun_glare=0.5)),
    "terrain": Spec(
        lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin(), TerrainPlugin(cells=24)], TerrainPlugin,
        look((0.0, 50.0, 130.0), target=(0.0, 0.0, 0.0)),
        dict(size=128.0, cells=12, relief=60.0, horizon=0.0, snowline=0.2, rock_slope=0.05)),
    "sky": Spec(
        lambda: [DefaultPlugins(overlay=False), SkyPlugin(star_density=0.5), GroundPlugin()], SkyPlugin,
        look((0.0, 2.0, 0.0), yaw=math.radians(200.0), pitch=0.45),
        dict(turbidity=8.0, scale=0.08, sun_size_deg=4.0, sun_gain=200.0, sun_glare=0.5, night=(0.2, 0.1, 0.3), stars=False,
             star_density=0.9, star_brightness=40.0, twinkle=1.0, model="physical", aerial_perspective=True,
             aerial_steps=1, aerial_froxels=(4, 4, 2), **PHYSICAL_CHANGES),
        before={"sun_gain": configure_first(sun_size_deg=4.0), "night": set_sun(NIGHT), "stars": set_sun(NIGHT), "star_density": set_sun(NIGHT),
                "star_brightness": set_sun(NIGHT), "twinkle": set_sun(NIGHT),
                **{name: configure_first(model="physical") for name in PHYSICAL_CHANGES},
                "aerial_perspective": physical_ground(),
                "aerial_steps": physical_ground(400.0, aerial_perspective=True, aerial_froxels=None),   # the per-pixel march's
                "aerial_froxels": physical_ground(aerial_perspective=True)}),
    "sky_layer": Spec(
        lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin(), SkyLayerPlugin(size=32)], SkyLayerPlugin,
        look((123.0, 3.0, -77.0), yaw=0.3, pitch=0.6),
        dict(emptiness=0.1, sharpness=0.9, thickness=6.0, color=(0.9, 0.1, 0.1), lit_color=(0.1, 0.9, 0.1),
             altitude=600.0, tile_size=1500.0, horizon_fade=0.9, wind=((0.02, 0.0),) * 4, size=16,
             base_frequency=9, seed=7, light_step=0.2, rebake_tolerance=0.0, animate=False),
        observe={"rebake_tolerance": lambda app, plugin: plugin.octaves.bakes},
        # a sun turned by less than the default tolerance: only a tolerance of 0 re-bakes for it
        before={"rebake_tolerance": lambda app, plugin: plugin.configure(rebake_tolerance=1.0)},
        warm=2.0),
    "volumetric_fog": Spec(      # a SkyPlugin: its light is the fog's ambient with ambient_from="sky"
        lambda: [DefaultPlugins(overlay=False), SkyPlugin(), GroundPlugin(),
                 VolumetricFogPlugin(center=(0.0, 1.0, -10.0), scale=(8.0, 2.0, 8.0), falloff=0.5, bias=0.3,
                                     absorption=0.3, steps=16, light_steps=2, max_distance=60.0, octaves=3)],
        VolumetricFogPlugin,
        look((0.0, 3.0, 10.0), yaw=0.0, pitch=-0.1),
        dict(center=(3.0, 0.0, -12.0), scale=(4.0, 3.0, 4.0), bias=0.6, falloff=0.2, frequency=0.5, octaves=5,
             seed=9, wind=(-4.0, 1.0, 3.0), absorption=0.05, steps=40, light_steps=6, light_step=0.5,
             max_distance=12.0, ambient=(0.9, 0.1, 0.1), scattering=(0.1, 0.1, 0.9), animate=False,
             ambient_from="sky", froxels=(8, 6, 12), froxel_history=0.5, noise="filtered", cloud_shadows=False),
        # from froxels whose frames stand alone (froxel_history 1) to a history, which jitters the next frame
        before={"froxel_history": configure_first(froxels=(8, 6, 12), froxel_history=1.0)},
        # Mesa's texture unit blends in float: the hashed and the filtered noise give the same pixels there;
        # the frame compiles (and runs) the filtered variant
        observe={"noise": lambda app, plugin: {dict(key[1]).get("FOG_NOISE_FILTERED") for key in app.gpu._programs},
                 # cloud_shadows acts only under clouds (tests/test_volumetric_fog.py renders it): the setting read
                 "cloud_shadows": lambda app, plugin: plugin.settings.cloud_shadows}),
    "fog": Spec(
        lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(),
                 FogPlugin(mode="hetero_exp2", density=0.06, resolutions=(4, 8, 8, 16), tile_size=32.0)],
        FogPlugin,
        look((0.0, 3.0, 10.0), yaw=0.0, pitch=-0.05),
        dict(mode="exp", density=0.01, fog_color=(0.9, 0.1, 0.1), start=5.0, end=30.0, sky="keep", octaves=2,
             resolutions=(2, 4, 8, 8), winds=((5.0, 0.0, 0.0),) * 4, tile_size=64.0, amplitude=0.3,
             noise="procedural", texels_per_cell=2, seed=11, time_offset=3.0, color_from="sky", height_base=3.0,
             scale_height=0.5, sun_scattering=0.5, **{"phase.g": -0.3, "phase.g2": 0.8, "phase.w": 0.6}),
        before={"start": configure_first(mode="linear"), "end": configure_first(mode="linear"),
                "height_base": configure_first(mode="height", density=0.05),
                "scale_height": configure_first(mode="height", density=0.05),
                **{f"phase.{k}": configure_first(sun_scattering=0.5) for k in ("g", "g2", "w")}}),
    "light_shafts": Spec(     # the screen mode; the march's fields under the clouds (march_under_clouds)
        lambda: [DefaultPlugins(overlay=False), clouds(shading=False), SkyGradientPlugin(), GroundPlugin(),
                 LightShaftsPlugin(mode="screen")],
        LightShaftsPlugin,
        look((0.0, 2.0, 10.0), yaw=0.0, pitch=0.05),
        dict(samples=8, density=0.4, decay=0.7, weight=0.3, exposure=2.0, threshold=0.2, ceiling=0.05, radius=0.1,
             downsample=4, horizon_fade=0.9, front_fade=1.0, edge_fade=2.0, mode="march", steps=3,
             scattering=1e-4, max_distance=400.0, sun_intensity=2.0, **{"phase.g": 0.0, "phase.g2": 0.6, "phase.w": 0.7},
             fog_sun_share=0.3, froxels=(8, 6, 12), froxel_history=0.5),
        before={"__all__": sun_at((0.5, 0.55)), "edge_fade": sun_at((1.15, 0.55)), "steps": march_per_texel,
                **{f: march_under_clouds for f in ("scattering", "max_distance", "phase.g", "phase.g2", "phase.w",
                                                    "sun_intensity", "froxels", "froxel_history")}},
        # fog_sun_share acts only with a FogPlugin (tests/test_light_shafts_fog.py renders it): the setting read
        observe={"downsample": resource_size(MASK), "fog_sun_share": lambda app, plugin: plugin.settings.fog_sun_share}),
    "template_volume": Spec(
        lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(),
                 TemplateVolumePlugin(resolution=(16, 8, 16), slices=4, march_steps=24)], TemplateVolumePlugin,
        look((0.0, 8.0, 30.0), target=(0.0, 7.0, 0.0)),
        {"step_seconds": 1.0, "box.center": (4.0, 9.0, 2.0), "box.size": (10.0, 4.0, 20.0), "march_steps": 4},
        # the sliced job is paused: step_seconds drives the animation time of the next step it begins
        observe={"step_seconds": lambda app, plugin: (plugin._begin_step(3), plugin._time)[1]}),
    "daylight": Spec(
        lambda: [DefaultPlugins(overlay=False), DaylightPlugin(hours=15.0), SkyPlugin(stars=False), GroundPlugin()],
        DaylightPlugin,
        look((0.0, 2.0, 0.0), yaw=math.radians(240.0), pitch=0.2),
        dict(hours=9.0, speed=20.0, latitude=-30.0, day_of_year=355.0, year=1900, longitude=100.0, utc_offset=3.0),
        before={"year": configure_first(day_of_year=80.0), "utc_offset": configure_first(longitude=0.0)},
        frame_dt={"speed": 0.1}),
    "cloud_shadows": Spec(
        lambda: [DefaultPlugins(overlay=False), clouds(shading=False, edge_fade=0.5), SkyGradientPlugin(), GroundPlugin(),
                 CloudShadowsPlugin(), CloudFarFieldPlugin(size=32, tile_size=1000.0)],
        CloudShadowsPlugin,
        look((320.0, 400.0, 900.0), target=(320.0, 0.0, 320.0), far=6000.0),
        dict(base_altitude=900.0, cell_size=(10.0, 30.0, 10.0), sigma=0.05, strength=0.2, direct_fraction=0.3,
             horizon_fade=0.95, far_field=False),
        # sigma acts inside the volume only, whose few clouds' shadows lie out of the oblique view
        before={"sigma": lambda app, plugin: look((320.0, 2000.0, 320.0), target=(320.0, 0.0, 321.0))(app)},
        sun=Sun.from_angles(50.0, 30.0)),
    "cloud_render": Spec(
        lambda: [DefaultPlugins(overlay=False), clouds(cover=6), SkyGradientPlugin(), GroundPlugin(),
                 CloudRenderPlugin()],
        CloudRenderPlugin,
        look((320.0, 60.0, 500.0), target=(320.0, 360.0, 100.0), far=6000.0),     # some columns out of view
        dict(base_altitude=200.0, size_factor=6.0, sigma=0.05, frustum_culling=False, empty_space_skipping=False,
             max_point_size=1.0, downsample=4, lod_pixels=40.0, ms_attenuation=0.1, ms_contribution=1.0,
             ms_eccentricity=0.0, ms_diffusion=2.0, splat="compute", enabled=False),
        observe={"frustum_culling": culling_counters, "empty_space_skipping": culling_counters,
                 "downsample": resource_size(CLOUD_COLOR), "splat": splatted}),
    "cloud_far_field": Spec(
        lambda: [DefaultPlugins(overlay=False), clouds(cover=20, edge_fade=0.5), SkyGradientPlugin(), GroundPlugin(),
                 CloudRenderPlugin(), CloudFarFieldPlugin(size=32)],
        CloudFarFieldPlugin,
        look((320.0, 60.0, 320.0), yaw=0.3, pitch=0.15, far=60000.0),     # the horizon beyond the volume
        dict(thickness=0.5, tile_size=1000.0, wind=(500.0, 0.0), horizon_fade=0.9,
             size=16, base_frequency=9, seed=7, light_step=0.2, animate=False, enabled=False),
        before={"animate": configure_first(wind=(500.0, 0.0))}, observe={"light_step": light_channels}),
}


def _clouds_spec():
    weather = example_weather((32, 8, 32), 20)
    changes = dict(step_seconds=3.0, cover_threshold=6.0, sigma_t=2.0, scattering=Scattering("multiple-forward"),
                   albedo=0.5, sun_intensity=2.0, **{"phase.g": 0.2, "phase.g2": 0.6, "phase.w": 0.7}, sky_intensity=4.0,
                   ground_albedo=1.0,
                   cell_size=(10.0, 30.0, 10.0), base_altitude=150.0, edge_fade=0.8)
    changes.update(weather_changes(weather))
    observe = {"step_seconds": next_step_reads("dt"), "cover_threshold": lambda app, plugin: plugin.simulation.cover(),
               "scattering": shading_extinction}
    observe.update({f"weather.{name}": next_step_reads(name) for name in live_fields(WeatherPlugin)})
    # no ground plane: its GroundSurface would stand for ground_albedo
    return Spec(lambda: [DefaultPlugins(overlay=False), clouds(cover=20), SkyGradientPlugin(), CloudRenderPlugin()],
                CloudsPlugin, look((320.0, 60.0, 1100.0), target=CLOUD_CENTER, far=6000.0), changes, observe=observe)


def weather_changes(weather, prefix="weather."):
    """A new value for every live WeatherSettings field, valid beside the others."""
    return {f"{prefix}{k}": v for k, v in dict(
        cloud_density=weather.cloud_density + 7, density_adaption=weather.density_adaption + 3,
        cloud_size=weather.cloud_size + 1.0, cloud_size_variance=weather.cloud_size_variance / 2,
        vertical_scale=weather.vertical_scale * 2, altitude=0.3, altitude_variance=0.05,
        lifetime=weather.lifetime * 2, lifetime_variance=weather.lifetime_variance / 2,
        shrink_time=weather.shrink_time + 2.0, region_margin=weather.region_margin + 3.0,
        wind=(-1.0, 0.0, 2.0), wind_variance=weather.wind_variance + 0.3, wind_field=np.ones((2, 2, 2)),
        hum_scale=0.5, act_scale=0.05, ext_scale=0.3, vanish_threshold=0.01).items()}


def _weather_spec():
    weather = example_weather((16, 8, 16), 10)
    changes = weather_changes(weather, prefix="")
    return Spec(lambda: [DefaultPlugins(overlay=False), GroundPlugin(), WeatherPlugin(weather, seed=1)],
                WeatherPlugin, look((0.0, 3.0, 10.0), yaw=0.0, pitch=0.0), changes,
                observe={name: next_step_reads(name) for name in changes},
                frame_dt={name: 1 / 30 for name in changes})         # one fixed step per frame


def _aimed(app, plugin):
    """Where the weather is (the cover it aims at) and what the clouds were told (their ellipsoids, extinction)."""
    return plugin.cover, plugin.clouds.settings.weather.cloud_density, plugin.clouds.settings.sigma_t


SPECS["clouds"] = _clouds_spec()
SPECS["antialias"] = Spec(
    lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(), MeshPlugin(), AntialiasPlugin()],
    AntialiasPlugin, look((0.0, 3.0, 10.0), yaw=0.3, pitch=0.02),
    dict(span_max=1.0, reduce_mul=1.0, reduce_min=1.0, mode="taa", history=0.5, motion=False),
    # the temporal mode past its running mean (1 / (n + 1) below the history's weight): the weight it blends with
    before={"history": lambda app, plugin: [configure_first(mode="taa")(app, plugin)] + [render(app) for _ in range(12)],
            "motion": configure_first(mode="taa")},
    # the meshes' motion target: drawn (and read) only while the temporal pass follows it
    observe={"history": lambda app, plugin: plugin.taa.weight,
             "motion": lambda app, plugin: MOTION in app.graph.compile().resources})
def adapting_from(offset):
    """One frame's adaptation from ``offset`` EV off the metered target (the camera's speeds show there)."""
    def observe(app, plugin):
        plugin.reset(plugin.read_state()["target"] + offset)
        render(app, 1 / 30)
        return plugin.read_state()["ev100"]
    return observe


SPECS["physical_camera"] = Spec(
    lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin(), GroundPlugin(), PhysicalCameraPlugin()],
    PhysicalCameraPlugin, look((0.0, 3.0, 10.0), yaw=0.3, pitch=0.02),
    dict(auto_exposure=False, ev100=3.0, compensation=-1.0, ev_range=(8.0, 14.0), metering_filter=(0.0, 0.1),
         speed_up=6.0, speed_down=3.0, transition=0.2, bloom=0.5, bloom_levels=2, enabled=False),
    observe={"speed_up": adapting_from(-3.0), "speed_down": adapting_from(3.0), "transition": adapting_from(-0.5),
             # the metered target moves at once; the exposure follows it at the camera's speeds (frozen here)
             **{name: lambda app, plugin: plugin.read_state()["target"]
                for name in ("compensation", "ev_range", "metering_filter")}},
    before={"ev100": configure_first(auto_exposure=False), "bloom_levels": configure_first(bloom=0.5)})
SPECS["cloud_weather"] = Spec(
    # the sprites, no far field: one frame is the next at dt 0 (the march, which would draw the far field,
    # turns its samples every frame)
    lambda: [DefaultPlugins(overlay=False), SkyGradientPlugin(),
             CloudSky("fair_weather", warmup_steps=1, renderer="sprites", horizon=False)],
    CloudWeatherPlugin, look((0.0, 300.0, 0.0), pitch=0.9, far=20000.0),
    dict(preset="overcast", cover=0.9, transition=5.0),
    observe={"preset": _aimed, "cover": _aimed, "transition": lambda app, plugin: plugin.settings.transition},
    before={"preset": configure_first(transition=0.0), "cover": configure_first(transition=0.0)},   # settled first
    frame_dt={"preset": 1 / 30, "cover": 1 / 30})
SPECS["weather"] = _weather_spec()
SPECS["cloud_top_view"] = Spec(
    lambda: [DefaultPlugins(overlay=False), clouds(cover=20), CloudTopViewPlugin()], CloudTopViewPlugin,
    look((0.0, 3.0, 10.0), yaw=0.0, pitch=0.0), dict(full_column=0.5))


def _raymarch_scene():
    density = np.zeros((16, 4, 16), np.float32)
    density[4:12, 0:3, 4:12] = 1.0
    medium = CloudSettings(cell_size=(20.0, 30.0, 20.0), base_altitude=300.0, group_size=(4, 4), smoothing_slices=1,
                           sigma_t=0.01)
    return [DefaultPlugins(overlay=False), CloudsPlugin(medium, density=density), SkyGradientPlugin(), GroundPlugin(),
            RaymarchCloudsPlugin(resolution=1, jitter=False, steps=64), CloudFarFieldPlugin(size=32)]


def raymarch_history(app, plugin):
    """Whether the ray march's temporal resolve holds a history."""
    return next(p for p in app.graph.passes if p.name == "cloud_raymarch").temporal.allocated


def raymarch_skip_map(app, plugin):
    """Whether the ray march holds an uploaded skip map (empty-space skipping changes no pixel)."""
    return next(p for p in app.graph.passes if p.name == "cloud_raymarch").skip is not None


def raymarch_far_distance(app, plugin):
    """The far-field march's end distance as the last frame's program holds it (this view's far
    clouds end in the haze before either value)."""
    return next(p for p in app.graph.passes if p.name == "cloud_raymarch").program(True)["far_distance"].value


def raymarch_turn(app, plugin):
    """The ray march's frame just after a small camera turn, from a converged history (the history
    knobs act only while the camera moves); the camera is put back."""
    rp = next(p for p in app.graph.passes if p.name == "cloud_raymarch")
    cam = app.resource(Camera)
    yaw = cam.yaw
    rp.temporal.reset()
    rp.frame_index = 0
    try:
        for _ in range(4):
            app.render()
        cam.yaw = yaw + 0.05
        return app.read_linear()
    finally:
        cam.yaw = yaw


_DETAIL = configure_first(detail_octaves=3)
_TEMPORAL = configure_first(resolution=2, reprojection=True)
SPECS["cloud_raymarch"] = Spec(
    _raymarch_scene, RaymarchCloudsPlugin, look((160.0, 360.0, -300.0), target=(160.0, 360.0, 160.0), far=6000.0),
    dict(base_altitude=250.0, steps=2, step=4.0, step_growth=0.05, empty_space_skipping=False, min_transmittance=0.5,
         jitter=True, resolution=2, reprojection=False, history_clamp=0.0, motion_limit=1.0, detail_octaves=1, detail_scale=300.0, detail_strength=0.5,
         sun_steps=2, wind=(400.0, 0.0, 0.0), ms_attenuation=0.9, ms_contribution=1.0, ms_eccentricity=0.0,
         ms_diffusion=0.0, far_field=False, far_distance=1000.0, far_step_growth=0.3, cloud_type=1.0, volume=False,
         enabled=False,
         # stratus over the west half of the volume, congestus over the east (the default: cumulus)
         type_map=CloudTypeMap(np.array([[0.0, 0.0, 1.0, 1.0]]), origin=(0.0, -1e4), size=(320.0, 2e4))),
    observe={"resolution": resource_size(RAYMARCH_LOW_COLOR), "reprojection": raymarch_history,
             "empty_space_skipping": raymarch_skip_map, "history_clamp": raymarch_turn,
             "motion_limit": raymarch_turn, "far_distance": raymarch_far_distance},
    before={"reprojection": configure_first(resolution=2), "detail_scale": _DETAIL, "detail_strength": _DETAIL,
            "sun_steps": _DETAIL, "wind": _DETAIL, "history_clamp": _TEMPORAL, "motion_limit": _TEMPORAL})


CASES = [(name, f) for name, spec in SPECS.items() for f in live_fields(spec.kind, nested=True)]


# -- building and running the scenes ------------------------------------------------------------------
_APPS: dict = {}


@pytest.fixture(scope="module")
def scenes(small_gpu):
    with pytest.MonkeyPatch.context() as patch:         # the weather rules record what each step reads
        for module in (weather_system, cloud_simulation):
            patch.setattr(module, "step_weather", recording(module.step_weather))
        yield lambda name: _scene(small_gpu, name)
        for app, _, _ in _APPS.values():
            app.close()
        _APPS.clear()


def _scene(gpu, name):
    """(app, plugin under test, its original settings), built once per module and reset per test."""
    spec = SPECS[name]
    if name not in _APPS:
        app = App(gpu).add_plugins(*spec.make())
        app.graph.add_pass(CapturePass())
        app.insert_resource(Sun(np.array(spec.sun.direction), spec.sun.color))
        spec.camera(app)
        plugin = next(p for p in app.plugins if isinstance(p, spec.kind))
        app.run_frames(max(1, int(spec.warm / 0.25)), dt=0.25)   # start-up, then animation time > 0
        for job in list(app.frames.jobs):
            app.frames.remove(job)                          # a frozen scene: sliced jobs paused
        _APPS[name] = (app, plugin, plugin.settings)
    app, plugin, original = _APPS[name]
    plugin.configure(**{f: getattr(original, f) for f in live_fields(plugin)})
    if isinstance(plugin, DaylightPlugin):
        app.resource(TimeOfDay).hours = original.hours
    app.insert_resource(Sun(np.array(spec.sun.direction), spec.sun.color))
    spec.camera(app)
    return app, plugin, spec


def render(app, dt=0.0):
    app.update(dt)
    assert app.gpu.ctx.error == "GL_NO_ERROR"


# -- the tests ----------------------------------------------------------------------------------------
def test_every_live_setting_of_every_plugin_has_a_case():
    for name, spec in SPECS.items():
        missing = set(live_fields(spec.kind, nested=True)) - set(spec.changes)
        assert not missing, f"{spec.kind.__name__}: live settings without a case: {sorted(missing)}"
        extra = set(spec.changes) - set(live_fields(spec.kind, nested=True))
        assert not extra, f"{spec.kind.__name__}: cases for fields that are not live settings: {sorted(extra)}"


def test_every_plugin_follows_the_convention():
    """One frozen settings dataclass per plugin, made from keywords and from a settings object alike."""
    for spec in SPECS.values():
        cls = spec.kind.settings_class
        assert cls.__name__.endswith("Settings") and dataclasses.is_dataclass(cls)
        assert cls.__dataclass_params__.frozen, f"{cls.__name__} must be frozen"
        default = cls()
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(default, dataclasses.fields(cls)[0].name, None)


@pytest.mark.parametrize("name, setting", CASES, ids=[f"{n}.{f}" for n, f in CASES])
def test_a_live_change_shows_on_the_next_frame(scenes, name, setting):
    app, plugin, spec = scenes(name)
    for hook in (spec.before.get("__all__"), spec.before.get(setting)):
        if hook is not None:
            hook(app, plugin)
    observe = spec.observe.get(setting, pixels)
    dt = spec.frame_dt.get(setting, 0.0)
    render(app, dt)
    before = observe(app, plugin)
    render(app, dt)
    assert same(observe(app, plugin), before), "the scene is not frozen: an unchanged frame differs"
    new = spec.changes[setting]
    if setting == "rebake_tolerance":
        sun = app.resource(Sun)                                     # turned a little: within tolerance 1
        sun.direction = Sun.from_angles(31.0, 201.0).direction
        render(app, dt)
        before = observe(app, plugin)
    settings = plugin.configure(**nested_change(setting, new))
    assert plugin.settings is settings and same(nested_value(settings, setting), new)
    render(app, dt)
    assert not same(observe(app, plugin), before), f"{type(settings).__name__}.{setting} = {new!r} changed nothing"


REJECTED = [
    ("sky", dict(turbidity=5.0, scale=-1.0), "SkySettings.scale"),
    ("sky", dict(turbidity=5.0, nosuch=1), "unknown SkySettings setting(s) nosuch"),
    ("ground", dict(albedo=(1, 1)), "GroundSettings.albedo must be 3 non-negative numbers"),
    ("render_core", dict(exposure=0.0), "RenderCoreSettings.exposure must be a finite number > 0.0"),
    ("light_shafts", dict(exposure=1.0, downsample=0), "LightShaftSettings.downsample must be a whole number 1..8"),
    ("light_shafts", dict(downsample=3, colour=1), "unknown LightShaftSettings setting(s) colour"),
    ("fog", dict(density=0.01, amplitude=2.0), "FogSettings.amplitude"),
    ("terrain", dict(relief=5.0, cells=0), "TerrainSettings.cells must be a whole number 1..1024"),
    ("overlay", dict(visible="yes"), "OverlaySettings.visible must be True or False"),
    ("cloud_render", dict(size_factor=2.0, lod_pixels=0.0), "CloudRenderSettings.lod_pixels"),
    ("daylight", dict(latitude=95.0), "DaylightSettings.latitude must be a finite number >= -90.0 and <= 90.0"),
    ("template_volume", dict(march_steps=8, resolution=(32, 8, 16)), "TemplateVolumeSettings.resolution cannot change"),
    ("template_volume", dict(slices=2), "TemplateVolumeSettings.slices cannot change"),
]


@pytest.mark.parametrize("name, changes, message", REJECTED, ids=[f"{n}-{'-'.join(c)}" for n, c, _ in REJECTED])
def test_a_rejected_change_raises_and_leaves_everything_as_it_was(scenes, name, changes, message):
    app, plugin, spec = scenes(name)
    if spec.before.get("__all__") is not None:
        spec.before["__all__"](app, plugin)
    render(app)
    shown = pixels(app, plugin)
    settings = plugin.settings
    compiled = app.graph.compile()
    with pytest.raises(ValueError) as error:
        plugin.configure(**changes)
    assert message in str(error.value)
    assert plugin.settings is settings
    render(app)
    assert app.graph.compile() is compiled, "the render graph recompiled"
    assert same(pixels(app, plugin), shown), "a rejected change showed"


def test_fixed_settings_are_documented_and_refused_by_name():
    plugin = TemplateVolumePlugin(resolution=(16, 8, 16), slices=4)
    assert type(plugin.settings).FIXED == ("resolution", "slices")
    assert plugin.configure(resolution=(16, 8, 16)).resolution == (16, 8, 16)   # not a change
    with pytest.raises(ValueError, match=r"TemplateVolumeSettings\.resolution, TemplateVolumeSettings\.slices cannot change"):
        plugin.configure(resolution=(8, 8, 8), slices=2)


def test_construction_takes_a_settings_object_and_keywords_on_top():
    base = LightShaftsPlugin(samples=12).settings
    plugin = LightShaftsPlugin(base, exposure=0.25)
    assert (plugin.settings.samples, plugin.settings.exposure) == (12, 0.25)
    with pytest.raises(ValueError, match="LightShaftsPlugin settings must be a LightShaftSettings, got SkySettings"):
        LightShaftsPlugin(SkyPlugin().settings)

    class Bare(Plugin):
        pass
    assert Bare().settings is None
    with pytest.raises(ValueError, match="Bare takes no settings, got exposure"):
        Bare(exposure=1.0)
    with pytest.raises(ValueError, match="Bare has no settings to configure"):
        Bare().configure(exposure=1.0)
