"""The second example game, played headless with a script: burning climbs and venting sinks, the wind
veers with height, a ring flown through scores and goes, touching the ground lands the balloon and a
new race starts three seconds later; the frame shows the balloon under the chase camera."""
import numpy as np

from atmos import Input, Label, Transform, key
from atmos.demo_registry import DemoSettings
from atmos.gpu import create_headless
from atmos.render_core import CapturePass
from atmos.runner import build_app


def test_the_balloon_race_plays_headless():
    from atmos.demos.balloon import RINGS, Race, wind
    gpu = create_headless((96, 54))
    capture = CapturePass()
    try:
        app = build_app("balloon", DemoSettings(size=gpu.size, headless=True), gpu, start=False)
        app.graph.add_pass(capture)
        app.run_frames(2, 1 / 30)
        race, inp = app.resource(Race), app.resource(Input)
        balloon = app.world.component_for_entity(race.balloon, Transform)
        assert app.state == "race" and race.races == 1 and len(race.rings) == RINGS
        assert app.world.component_for_entity(race.hud["score"], Label).text == f"rings 0/{RINGS}"
        assert capture.depth[27, 48] < 1.0, "the chase camera has the balloon in the middle of the frame"

        height = balloon.position[1]
        inp.press(key.SPACE)                                   # burn: the balloon climbs
        app.run_frames(20, 0.1)                                # 2 s (frames of the clock's longest delta)
        inp.release(key.SPACE)
        assert race.climb > 1.0 and balloon.position[1] > height + 2.0
        assert not np.allclose(wind(50.0), wind(300.0), atol=1.0), "height steers"

        ring = race.rings[0]
        where = app.world.component_for_entity(ring, Transform).position
        balloon.teleport(where + (0.0, 0.0, 5.0))
        race.climb = 0.0
        app.run_frames(3, 1 / 30)
        assert race.score == 1 and ring not in race.rings and not app.world.has_entity(ring)

        ground = race.terrain.height_at(balloon.position[0], balloon.position[2])
        balloon.teleport((balloon.position[0], ground + 12.0, balloon.position[2]))
        inp.press(key.V)                                       # vent into the ground: landed
        for _ in range(30):                                    # 3 s at most
            app.update(0.1)
            if app.state == "landed":
                break
        inp.release(key.V)
        assert app.state == "landed"
        app.update(1 / 30)                                     # the HUD of the first landed frame
        assert app.world.component_for_entity(race.hud["message"], Label).text.startswith("landed")
        app.run_frames(31, 0.1)                                # 3 s later: a new race
        assert app.state == "race" and race.races == 2 and race.score == 0 and len(race.rings) == RINGS
        app.close()
    finally:
        gpu.release()
