"""flight: a camera flying fast above, through and below the cloud layer in a holding pattern; with the ray
march (the default) the deck has relief: cumulus here, congestus towering above it there."""
import math

import numpy as np

from atmos.camera import Camera
from atmos.demo_registry import DemoSettings
from atmos.demos._cloudscape import (BASE_ALTITUDE, CELL, SHAPE, build_cloudscape, follow_camera, region_offsets,
                                     regional_types)
from atmos.plugins.clouds.raymarch import CLOUD_TYPES, RaymarchCloudsPlugin

TITLE = "a fast camera flying a holding pattern above, through and below the cloud layer"
DEFAULT_FRAMES = 300
SPEED = 160.0        # m/s
LEG = 2400.0         # m, straight legs of the racetrack
RADIUS = 900.0       # m, the turns
TYPE_SPREAD = 0.45   # the march's cloud types: cumulus ± this by region (congestus towers where it passes 0.5)


def holding_pattern(t: float) -> tuple[np.ndarray, float]:
    """Position and heading on a racetrack (two straight legs, two half-circle turns) at time ``t``."""
    lap = 2 * LEG + 2 * math.pi * RADIUS
    s = (SPEED * t) % lap
    if s < LEG:                                           # northbound leg on x = +RADIUS
        return np.array([RADIUS, 0.0, LEG / 2 - s]), 0.0
    s -= LEG
    turn = math.pi * RADIUS
    if s < turn:                                          # turn west over the north end
        a = s / RADIUS
        return np.array([RADIUS * math.cos(a), 0.0, -LEG / 2 - RADIUS * math.sin(a)]), -a
    s -= turn
    if s < LEG:                                           # southbound leg on x = -RADIUS
        return np.array([-RADIUS, 0.0, -LEG / 2 + s]), -math.pi
    a = (s - LEG) / RADIUS                                # turn east over the south end
    return np.array([-RADIUS * math.cos(a), 0.0, LEG / 2 + RADIUS * math.sin(a)]), -math.pi - a


def fly(app) -> None:
    if app.resource(DemoSettings).headless:
        t = app.clock.frame_time
        position, heading = holding_pattern(t)
        top = BASE_ALTITUDE + SHAPE[1] * CELL[1]
        middle, amplitude = (BASE_ALTITUDE + top) / 2, (top - BASE_ALTITUDE) / 2 + 250.0
        position[1] = middle + amplitude * math.sin(2 * math.pi * t / 20.0)   # above, through, below
        cam = app.resource(Camera)
        cam.position = position
        cam.yaw = heading
        cam.pitch = math.radians(-4.0) * math.cos(2 * math.pi * t / 20.0)
    follow_camera(app)


def build(app, settings) -> None:
    build_cloudscape(app, settings, hours=11.0, cloud_density=170, warmup_steps=30, haze=True)
    march = next(p for p in app.plugins if isinstance(p, RaymarchCloudsPlugin))
    march.configure(type_map=regional_types(CLOUD_TYPES["cumulus"], region_offsets(settings.seed), TYPE_SPREAD))
    app.add_system(fly, "update", label="fly", after="fly_camera")
