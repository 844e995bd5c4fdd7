"""balloon: a hot-air balloon race at dawn on atmos. The wind carries you up a misty valley; burn to
rise (SPACE) and vent to sink (V). The wind veers with height, so height is how you steer. Fly
through the rings; touch the ground and you land, and a new race starts three seconds later.
``atmos run demos/balloon.py`` (or ``atmos demo balloon``).
"""
import math
from dataclasses import dataclass, field

import numpy as np

from atmos import (AntialiasPlugin, Camera, ChaseCameraPlugin, CloudSky, DaylightPlugin, DefaultPlugins, FogPlugin,
                   Input, Label, MeshInstance, MeshPlugin, Parent, SkyPlugin, TerrainPlugin, TextPlugin, Transform,
                   cylinder, key, sphere, torus)

TITLE = "a balloon race at dawn: ride the winds up a misty valley, through the rings"
DEFAULT_FRAMES = 300
START = np.array([0.0, 140.0, 0.0])
RINGS = 8
RING_RADIUS = 14.0


def wind(height: float) -> np.ndarray:
    """m/s over the ground (x, z): up the valley (−z), veering left low down and right up high."""
    turn = 0.8 * math.tanh((height - 160.0) / 100.0)
    return (7.0 + 0.02 * max(height, 0.0)) * np.array([math.sin(turn), -math.cos(turn)])


@dataclass
class Race:
    """The game's state (a resource)."""
    terrain: TerrainPlugin
    balloon: int = 0
    rings: list = field(default_factory=list)
    climb: float = 0.0                      # m/s up
    score: int = 0
    races: int = 0
    hud: dict = field(default_factory=dict)


def ring_positions(terrain: TerrainPlugin) -> list:
    """Along the wind's path from the start, each ring a little higher or lower than the last."""
    p, out = START.copy(), []
    for i in range(RINGS):
        height = 90.0 + 140.0 * (0.5 + 0.5 * math.sin(1.3 * i))
        for _ in range(160):                # 40 s of drift at the ring's height between rings
            p[[0, 2]] += wind(height) * 0.25
        ground = float(terrain.height_at(p[0], p[2]))
        out.append((p[0], ground + height, p[2]))
    return out


def start_race(app) -> None:
    race = app.resource(Race)
    for e in race.rings:
        app.world.delete_entity(e)
    ring = torus(RING_RADIUS, 1.2)
    race.rings = [app.world.create_entity(Transform(where, pitch=math.pi / 2), MeshInstance(ring, (0.9, 0.7, 0.1)))
                  for where in ring_positions(race.terrain)]
    app.world.component_for_entity(race.balloon, Transform).teleport(START)
    race.climb, race.score, race.races = 0.0, 0, race.races + 1


def fly(app) -> None:
    """Fixed step: burn or vent, a little sink, the wind of your height."""
    race, inp, dt = app.resource(Race), app.resource(Input), app.clock.step
    lift = 2.5 * ((key.SPACE in inp.keys) - (key.V in inp.keys)) - 0.3
    race.climb = float(np.clip(race.climb + (lift - 0.2 * race.climb) * dt, -6.0, 6.0))
    t = app.world.component_for_entity(race.balloon, Transform)
    w = wind(t.position[1])
    t.position = t.position + np.array([w[0], race.climb, w[1]]) * dt
    t.yaw = math.atan2(-w[0], -w[1])


def rings_and_ground(app) -> None:
    """Fixed step: a ring flown through scores; the basket touching the ground lands the balloon."""
    race = app.resource(Race)
    p = app.world.component_for_entity(race.balloon, Transform).position
    for e in list(race.rings):
        if np.linalg.norm(app.world.component_for_entity(e, Transform).position - p) < RING_RADIUS:
            app.world.delete_entity(e)
            race.rings.remove(e)
            race.score += 1
    if race.terrain.raycast(p, (0.0, -1.0, 0.0), max_distance=9.0) is not None:   # the basket is 8 m down
        app.set_state("landed")


def hud(app) -> None:
    race = app.resource(Race)
    p = app.world.component_for_entity(race.balloon, Transform).position
    texts = {"score": f"rings {race.score}/{RINGS}", "flight": f"{p[1]:.0f} m  climb {race.climb:+.1f} m/s",
             "message": "landed: a new race in 3 s" if app.state == "landed" else ""}
    for name, text in texts.items():
        app.world.component_for_entity(race.hud[name], Label).text = text


def build(app, settings) -> None:
    terrain = TerrainPlugin(size=9000.0, cells=96, relief=240.0, rock_slope=0.16)
    chase = ChaseCameraPlugin(distance=60.0, height=12.0)
    sky = CloudSky("fair_weather", seed=settings.seed, altitude=900.0, transition=30.0)
    app.add_plugins(DefaultPlugins(fly_camera=False), DaylightPlugin(hours=6.2, speed=0.05),
                    SkyPlugin(model=settings.sky), terrain, sky, MeshPlugin(), TextPlugin(design_height=540), chase,
                    FogPlugin(mode="height", density=0.006, height_base=0.0, scale_height=30.0, sky="keep",
                              sun_scattering=0.12, color_from="sky", fog_color=(1.0, 1.0, 1.0)), AntialiasPlugin(mode="taa"))
    cam = app.resource(Camera)
    cam.near, cam.far = 1.0, terrain.far_plane()
    balloon = app.world.create_entity(Transform(START.copy()), MeshInstance(sphere(9.0), (0.8, 0.2, 0.15)))
    app.world.create_entity(Transform((0.0, -13.0, 0.0)), MeshInstance(cylinder(1.6, 1.8), (0.45, 0.3, 0.15)),
                            Parent(balloon))
    race = Race(terrain, balloon)
    race.hud = {"score": app.world.create_entity(Label("", x=12, y=10, size=22)),
                "flight": app.world.create_entity(Label("", x=-12, y=10, size=18, anchor=(1.0, 0.0))),
                "message": app.world.create_entity(Label("", y=-20, size=28, anchor=(0.5, 0.5)))}
    app.insert_resource(race)
    chase.target = balloon
    app.add_state("race", "landed")
    app.on_enter("race", start_race)
    app.on_enter("landed", lambda app: app.after(3.0, lambda app: app.set_state("race"), in_state="landed"))
    app.add_system(fly, "simulate", label="balloon_fly", in_state="race")
    app.add_system(rings_and_ground, "simulate", label="balloon_rings", after="balloon_fly", in_state="race")
    app.add_system(hud, "update", label="balloon_hud")
    app.every(45.0, lambda app: sky.weather.configure(preset="broken" if sky.weather.settings.preset ==
                                                      "fair_weather" else "fair_weather"))
