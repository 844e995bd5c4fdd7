"""fog_valley: a ~10,000-triangle terrain and its far ring under Zdrojewska's heterogeneous fog.

By default height fog pooled in the valley with the paper's turbulence (preset ``valley``); the paper's
figures 6-10 with ATMOS_FOG_PRESET=fig6 ... fig10. In a window keys 1-6 switch: 1 the valley, 2-6 the figures.
"""
import math
import os

import numpy as np

from atmos.camera import Camera
from atmos.input import Input
from atmos.keys import key
from atmos.defaults import DefaultPlugins
from atmos.demo_registry import DemoSettings
from atmos.lighting import Sun
from atmos.plugins.fog import PAPER_RESOLUTIONS, FogPlugin
from atmos.plugins.sky_gradient import SkyGradientPlugin
from atmos.plugins.terrain import TerrainPlugin
from atmos.plugins.antialias import AntialiasPlugin

TITLE = "heterogeneous Perlin-turbulence fog over a 10,000-triangle valley (Zdrojewska 2004)"
DEFAULT_FRAMES = 60

PRESETS = {  # FogSettings fields
    # the default, not the paper's: height fog pooled in the valley, thinning upward, with its turbulence
    "valley": dict(mode="hetero_height", density=0.15, height_base=0.0, scale_height=2.0,
                   resolutions=PAPER_RESOLUTIONS["coarse"]),
    # the paper's figures: eq. (7) = hetero_exp2, eq. (6) = hetero_exp; fog thick enough to hide the hills
    "fig6": dict(mode="hetero_exp2", density=0.044, resolutions=PAPER_RESOLUTIONS["fine"]),
    "fig7": dict(mode="hetero_exp", density=0.044, resolutions=PAPER_RESOLUTIONS["fine"]),
    "fig8": dict(mode="hetero_exp2", density=0.044, resolutions=PAPER_RESOLUTIONS["coarse"]),
    "fig9": dict(mode="hetero_exp", density=0.044, resolutions=PAPER_RESOLUTIONS["coarse"]),
    "fig10": dict(mode="hetero_exp", density=0.06, resolutions=PAPER_RESOLUTIONS["coarse"]),
}
DEFAULT_PRESET = "valley"
TERRAIN_SIZE = 112.0
NOISE_TILE = 112.0  # metres per noise tile: the lowest octave's 16 cells are 7 m
CAMERA_POS = np.array([-3.0, 4.5, 44.0])
CAMERA_TARGET = (4.0, 2.5, 0.0)


def preset(name: str) -> dict:
    """The FogSettings fields of a preset."""
    if name not in PRESETS:
        raise ValueError(f"unknown fog preset {name!r}; allowed: {', '.join(PRESETS)}")
    return PRESETS[name]


def place_camera(app) -> None:
    """Headless runs fly slowly up the valley; in a window the fly camera is yours."""
    if not app.resource(DemoSettings).headless:
        return
    cam = app.resource(Camera)
    t = app.clock.frame_time
    cam.position = CAMERA_POS + np.array([6.0 * math.sin(0.3 * t), 0.0, -1.5 * t])
    cam.look_at(np.array(CAMERA_TARGET) + np.array([0.0, 0.0, -1.5 * t]))


def build(app, settings, fog_preset: str | None = None) -> FogPlugin:
    name = fog_preset or os.environ.get("ATMOS_FOG_PRESET", DEFAULT_PRESET)
    fog = FogPlugin(sky="fog", tile_size=NOISE_TILE, seed=settings.seed, **preset(name))   # --seed: the noise lattice
    app.insert_resource(Sun.from_angles(elevation_deg=30.0, azimuth_deg=-30.0))
    terrain = TerrainPlugin(size=TERRAIN_SIZE, relief=10.0, rock_slope=0.6)   # steep grassy hills, as in the paper
    app.add_plugins(DefaultPlugins(overlay=not settings.headless), SkyGradientPlugin(), terrain, fog,
                    AntialiasPlugin(mode="taa"))
    cam = app.resource(Camera)
    cam.position = CAMERA_POS.copy()
    cam.far = terrain.far_plane()
    cam.look_at(CAMERA_TARGET)

    def switch_preset(app) -> None:
        keys = app.resource(Input).pressed
        for number, name in zip((key._1, key._2, key._3, key._4, key._5, key._6), PRESETS):
            if number in keys:
                fog.configure(**PRESETS[name])

    app.add_system(place_camera, "update", label="fog_valley_camera", after="fly_camera")
    app.add_system(switch_preset, "update", label="fog_valley_presets")
    return fog
