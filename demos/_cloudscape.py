"""The cloud scene the sunset, flight and weather demos share (a module, not a demo: its name
starts with an underscore).

Terrain under a Preetham sky driven by the time of day; the cloud chain (weather → automaton →
smoothing → density maps → shading) sliced over frames; the clouds drawn as point sprites with both
cullings or ray-marched with detail noise (``DemoSettings.clouds``; key C flips them live: both
plugins are added; under the march the sprites are disabled, their pass culled; under the sprites the
march draws the far field alone; key X flips the sprites between compute splatting and blended points);
their ground shadows and light shafts. 40 m cells: a 128×16×128 volume covers 5 km × 640 m × 5 km
from 900 m up, centred on the camera.
"""
from __future__ import annotations

import numpy as np

from atmos.camera import Camera
from atmos.defaults import DefaultPlugins
from atmos.demo_registry import add_demo_camera
from atmos.input import Input
from atmos.plugins.antialias import AntialiasPlugin
from atmos.keys import key
from atmos.plugins.clouds.raymarch import CloudTypeMap, RaymarchCloudsPlugin
from atmos.plugins.clouds.sprites import CloudRenderPlugin
from atmos.plugins.clouds.far_field import CloudFarFieldPlugin
from atmos.plugins.clouds.shadows import CloudShadowsPlugin
from atmos.plugins.clouds import CloudSettings, CloudsPlugin
from atmos.plugins.clouds.presets import EDGE_FADE
from atmos.plugins.daylight import DaylightPlugin
from atmos.plugins.fog import FogPlugin
from atmos.plugins.light_shafts import LightShaftsPlugin
from atmos.plugins.sky import SkyPlugin
from atmos.plugins.terrain import TerrainPlugin
from atmos.plugins.clouds.weather import VolumeOrigin, example_weather

SHAPE = (128, 16, 128)
CELL = (40.0, 40.0, 40.0)
BASE_ALTITUDE = 900.0
# m: the terrain's far ring. Nearer than TerrainSettings' default: the haze hides what lies beyond, and
# the cloud shadow map's far cascade spans 1.25 x the camera's far plane (its texels grow with it).
HORIZON = 40000.0
REACH = 5000.0          # m: the cameras stay this near the origin (the far plane covers the ring from there)
REGIONS = 24            # texels per side of the ray march's cloud-type maps (regional_types)
REGION_SPAN = 12000.0   # m the type maps span, centred on the origin (the far field's clouds too)


def build_cloudscape(app, settings, *, hours: float, speed: float = 0.0, cloud_density: int = 140,
                     warmup_steps: int = 30, slices_per_frame: int = 3, wind=(0.6, 0.0, 0.25), haze: bool = False,
                     horizon: bool = True):
    """Add the whole scene to ``app``; returns the CloudsPlugin (``configure(weather={"cloud_density": n})``
    changes the cover live). ``haze``: a distance haze that hazes terrain and clouds by their own
    distance (:mod:`atmos.composition`), as ``settings.haze`` says: "fog", an exponential fog toward
    the horizon sky's colour (thicker than clear air: the stylised look), "air", the physical sky's
    aerial perspective (its own atmosphere and LUTs, ``SkySettings.aerial_perspective``), or "both",
    the air mixed with the fog along each ray (:func:`atmos.composition.media_mix`). ``horizon``:
    clouds to the horizon, the volume fading out over its outer EDGE_FADE into the far field
    (:mod:`atmos.plugins.clouds.far_field`)."""
    weather = example_weather(SHAPE, cloud_density=cloud_density, wind=wind)
    terrain = TerrainPlugin(size=40000.0, cells=71, relief=500.0, horizon=HORIZON,
                            rock_slope=0.08)                     # gentle hills: rock on the steepest
    clouds = CloudSettings(cell_size=CELL, base_altitude=BASE_ALTITUDE, smoothing_slices=8, group_size=(32, 32),
                           sigma_t=0.02, edge_fade=EDGE_FADE if horizon else 0.0)
    cloud_plugin = CloudsPlugin(clouds, weather=weather, seed=settings.seed, warmup_steps=warmup_steps)
    app.insert_resource(VolumeOrigin(-SHAPE[0] / 2, 0.0, -SHAPE[2] / 2))
    app.add_plugins(DefaultPlugins(overlay=not settings.headless),
                    DaylightPlugin(hours=hours, speed=speed),
                    SkyPlugin(model=settings.sky, aerial_perspective=haze and settings.haze in ("air", "both")),
                    terrain,
                    cloud_plugin,
                    CloudShadowsPlugin(),
                    CloudRenderPlugin(size_factor=4.0, enabled=settings.clouds == "sprites"),
                    RaymarchCloudsPlugin(volume=settings.clouds == "march"),   # else the far field alone
                    LightShaftsPlugin(horizon_fade=0.03),   # the sun's own colour already fades at the horizon
                    AntialiasPlugin(mode="taa"))
    app.add_system(switch_key, "update", label="cloud_renderer_switch")
    add_demo_camera(app, settings)
    if horizon:
        app.add_plugins(CloudFarFieldPlugin())
    if haze and settings.haze in ("fog", "both"):
        app.add_plugins(FogPlugin(mode="exp", density=4e-5, sky="keep", color_from="sky", fog_color=(1.0, 1.0, 1.0)))
    app.frames.slices_per_frame = slices_per_frame
    cam = app.resource(Camera)
    cam.near, cam.far = 1.0, terrain.far_plane(within=REACH)
    cam.position = np.array([0.0, 250.0, 0.0])
    return cloud_plugin


def region_offsets(seed: int) -> np.ndarray:
    """(REGIONS, REGIONS) offsets in [-1, 1] of each region's cloud type from the scene's: smooth blobs a
    few kilometres across (a coarse random grid, upsampled bilinearly and normalised)."""
    coarse = np.random.default_rng(seed).uniform(-1.0, 1.0, (6, 6))
    at = np.linspace(0.0, 5.0, REGIONS)
    i = np.minimum(at.astype(int), 4)
    f = at - i
    rows = coarse[i] * (1 - f)[:, None] + coarse[i + 1] * f[:, None]
    grid = rows[:, i] * (1 - f) + rows[:, i + 1] * f
    return grid / np.abs(grid).max()


def regional_types(kind: float, offsets: np.ndarray, spread: float) -> CloudTypeMap:
    """The ray march's types by region around ``kind``: each region off it by ``spread`` × its offset
    (:func:`region_offsets`), over REGION_SPAN metres around the origin."""
    return CloudTypeMap(np.clip(kind + spread * offsets, 0.0, 1.0), origin=(-0.5 * REGION_SPAN,) * 2,
                        size=(REGION_SPAN, REGION_SPAN))


def follow_camera(app) -> None:
    """Keep the simulation volume centred on the camera, in whole cells (the weather's region
    boundings keep clouds that drift out; the automaton advects by the volume's motion)."""
    cam = app.resource(Camera)
    origin = app.resource(VolumeOrigin)
    origin.x = float(np.floor(cam.position[0] / CELL[0] - SHAPE[0] / 2))
    origin.z = float(np.floor(cam.position[2] / CELL[2] - SHAPE[2] / 2))


def cloud_renderer(app) -> str:
    """"sprites" or "march": the renderer drawing the clouds now."""
    return "march" if _renderers(app)[1].settings.volume else "sprites"


def switch_clouds(app, clouds: str | None = None) -> str:
    """Draw the clouds with ``clouds`` ("sprites" or "march"; None: the other one); returns it. The
    sprites are disabled under the march (their pass declares nothing and is culled from the next
    frame); under the sprites the march draws the far field alone (``volume=False``), so the far
    clouds look the same with either renderer."""
    from atmos.demo_registry import DemoSettings
    clouds = clouds if clouds is not None else ("sprites" if cloud_renderer(app) == "march" else "march")
    DemoSettings(clouds=clouds)                      # checks the name
    sprites, march = _renderers(app)
    sprites.configure(enabled=clouds == "sprites")
    march.configure(volume=clouds == "march")
    return clouds


def switch_splat(app) -> str:
    """Flip how the sprites reach the pixels: splatted in compute or drawn as blended points (the
    default picks compute on a GPU, points on a software renderer); returns the new ``splat``."""
    sprites = _renderers(app)[0]
    return sprites.configure(splat="points" if sprites.splats() else "compute").splat


def switch_key(app) -> None:
    """Key C flips the cloud renderer; key X the sprites' splat (compute or points)."""
    pressed = app.resource(Input).pressed
    if key.C in pressed:
        switch_clouds(app)
    if key.X in pressed:
        switch_splat(app)


def _renderers(app) -> tuple:
    found = {type(p): p for p in app.plugins if isinstance(p, (CloudRenderPlugin, RaymarchCloudsPlugin))}
    return found[CloudRenderPlugin], found[RaymarchCloudsPlugin]
