"""glider: a small game on atmos. Glide over the hills through clouds and haze, collect the crates.

A/D (or the arrow keys) bank and turn, W/S nose down/up; diving gains speed, climbing costs it. Touch
the ground and the round starts again. ``atmos run demos/glider.py`` (or ``atmos demo glider``).
"""
import math
from dataclasses import dataclass, field

import numpy as np

from atmos import Camera, ChaseCameraPlugin, DefaultPlugins, Input, Transform, key
from atmos.plugins.antialias import AntialiasPlugin
from atmos.plugins.clouds import CloudSky
from atmos.plugins.daylight import DaylightPlugin, TimeOfDay
from atmos.plugins.fog import FogPlugin
from atmos.plugins.mesh import MeshInstance, MeshPlugin, box, glider
from atmos.plugins.sky import SkyPlugin
from atmos.plugins.terrain import TerrainPlugin
from atmos.plugins.text import Label, TextPlugin

TITLE = "a glider game: bank through clouds and haze over the hills, collect the crates"
DEFAULT_FRAMES = 300
START = np.array([0.0, 320.0, 0.0])
CRATES = 12
GRAVITY = 9.81


@dataclass
class Game:
    """The game's state (a resource): the glider, the crates left, the score and what the HUD says."""
    terrain: TerrainPlugin
    chase: ChaseCameraPlugin
    rng: np.random.Generator
    glider: int = 0
    crates: list = field(default_factory=list)
    speed: float = 32.0
    score: int = 0
    crashes: int = 0
    message_until: float = 0.0
    hud: dict = field(default_factory=dict)


def spawn_crates(app, game: Game) -> None:
    """A trail of crates ahead of the start, wandering left and right and down the hills."""
    for e in game.crates:
        app.world.delete_entity(e)
    crate, rng = box((6.0, 6.0, 6.0)), game.rng
    game.crates = []
    for i in range(CRATES):
        d = 120.0 + 110.0 * i
        where = START + (rng.uniform(-30, 30) + 40 * math.sin(i / 2), -12.0 * i - rng.uniform(0, 10), -d)
        game.crates.append(app.world.create_entity(Transform(where, yaw=rng.uniform(0, 6)),
                                                   MeshInstance(crate, (0.55, 0.35, 0.15))))


def reset(app, game: Game) -> None:
    t = app.world.component_for_entity(game.glider, Transform)
    t.teleport(START, yaw=0.0, pitch=0.0, roll=0.0)
    game.speed, game.score = 32.0, 0
    spawn_crates(app, game)
    game.chase.snap()


def fly(app) -> None:
    """Fixed step: steer from the keys, a banked turn, speed from the slope of the flight path."""
    game, inp, dt = app.resource(Game), app.resource(Input), app.clock.step
    t = app.world.component_for_entity(game.glider, Transform)
    bank = inp.axis(key.A, key.D) or inp.axis(key.LEFT, key.RIGHT)
    t.roll += (0.8 * bank - t.roll) * min(1.0, 3.0 * dt)
    t.pitch = float(np.clip(t.pitch + 0.6 * dt * (inp.axis(key.W, key.S) or inp.axis(key.UP, key.DOWN)), -0.7, 0.4))
    t.yaw += GRAVITY * math.tan(t.roll) / max(game.speed, 5.0) * dt
    game.speed = float(np.clip(game.speed - (GRAVITY * math.sin(t.pitch) + 0.0004 * game.speed ** 2) * dt + 0.25 * dt, 8, 90))
    t.position = t.position + (t.forward() * game.speed + (0.0, -1.2, 0.0)) * dt


def collect_and_crash(app) -> None:
    """Fixed step: crates within 9 m are collected; the ground ends the round."""
    game = app.resource(Game)
    p = app.world.component_for_entity(game.glider, Transform).position
    for e in list(game.crates):
        if np.linalg.norm(app.world.component_for_entity(e, Transform).position - p) < 9.0:
            app.world.delete_entity(e)
            game.crates.remove(e)
            game.score += 1
    ground = game.terrain.height_at(p[0], p[2])
    if p[1] < ground + 2.0:
        game.crashes += 1
        game.message_until = app.clock.time + 2.0
        reset(app, game)


def hud(app) -> None:
    game = app.resource(Game)
    p = app.world.component_for_entity(game.glider, Transform).position
    texts = {"score": f"crates {game.score}/{CRATES}", "flight": f"{p[1]:.0f} m  {game.speed * 3.6:.0f} km/h  "
             f"{app.resource(TimeOfDay).hours:05.2f} h",
             "message": "crashed: new round" if app.clock.time < game.message_until else ""}
    for name, text in texts.items():
        app.world.component_for_entity(game.hud[name], Label).text = text


def build(app, settings) -> None:
    terrain, chase = TerrainPlugin(size=12000.0, cells=96, relief=260.0, rock_slope=0.14), ChaseCameraPlugin(distance=16.0, height=4.0, bank=0.6)
    app.add_plugins(DefaultPlugins(overlay=False, fly_camera=False), DaylightPlugin(hours=16.5, speed=0.02),
                    SkyPlugin(model=settings.sky), terrain, CloudSky("fair_weather", seed=settings.seed, altitude=700.0),
                    FogPlugin(mode="exp", density=0.0001, sky="keep", color_from="sky", fog_color=(1.0, 1.0, 1.0)),
                    MeshPlugin(), TextPlugin(), chase, AntialiasPlugin(mode="taa"))
    cam = app.resource(Camera)
    cam.near, cam.far = 1.0, terrain.far_plane()
    glider_entity = app.world.create_entity(Transform(START.copy()), MeshInstance(glider(6.0), (0.85, 0.25, 0.15)))
    game = Game(terrain, chase, np.random.default_rng(settings.seed), glider=glider_entity)
    game.hud = {"score": app.world.create_entity(Label("", x=12, y=10, size=22)),
                "flight": app.world.create_entity(Label("", x=-12, y=10, size=18, anchor=(1.0, 0.0))),
                "message": app.world.create_entity(Label("", y=-20, size=28, color=(1, 0.6, 0.4, 1), anchor=(0.5, 0.5)))}
    app.insert_resource(game)
    chase.target = game.glider
    spawn_crates(app, game)
    app.add_system(fly, "simulate", label="glider_fly")
    app.add_system(collect_and_crash, "simulate", label="glider_collect", after="glider_fly")
    app.add_system(hud, "update", label="glider_hud")
