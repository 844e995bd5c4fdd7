"""ECS: a deleted entity is gone from the next stage's queries; spawning and deleting thousands a second
leaks nothing."""
import gc
import tracemalloc
from dataclasses import dataclass

import esper
import pytest

from atmos import App


@dataclass(slots=True)
class Pickup:
    value: int = 1


def test_a_deleted_entity_is_gone_from_the_next_stage_and_frame():
    app = App()
    e = app.world.create_entity(Pickup())
    seen = []

    def collect(app):
        if app.clock.frame == 2:
            app.world.delete_entity(e)
            app.world.delete_entity(e)                       # twice in one stage (two hits): fine
            seen.append(("update", [x for x, _ in app.world.get_component(Pickup)]))

    app.add_system(collect, "update", label="collect")
    app.add_system(lambda app: seen.append(("render", [x for x, _ in app.world.get_component(Pickup)])), "render",
                   label="draw")
    app.run_frames(3)
    assert seen == [("render", [e]), ("update", [e]), ("render", []), ("render", [])]
    assert not app.world.has_entity(e) and app.world.entity_count() == 0
    with pytest.raises(ValueError, match=f"entity {e} does not exist"):
        app.world.delete_entity(e)
    app.close()


def test_spawning_and_deleting_thousands_per_second_leaks_nothing():
    app = App()
    live = []

    def churn(app):
        for e in live[:200]:
            app.world.delete_entity(e)
        del live[:200]
        live.extend(app.world.create_entity(Pickup(i)) for i in range(200))

    counts = set()
    app.add_system(churn, "update", label="churn")
    app.add_system(lambda app: counts.add(len(app.world.get_component(Pickup))), "render", label="count")
    app.run_frames(300, 1 / 60)                               # warm up: caches and dicts at full size
    gc.collect()
    tracemalloc.start()
    app.run_frames(300, 1 / 60)
    gc.collect()
    before = tracemalloc.take_snapshot()
    app.run_frames(600, 1 / 60)                               # 120,000 entities made and deleted, 12,000 a second
    gc.collect()
    grown = sum(s.size_diff for s in tracemalloc.take_snapshot().compare_to(before, "filename"))
    tracemalloc.stop()
    assert counts == {200}, "every frame draws exactly the live entities"
    assert app.world.entity_count() == 200 and len(esper._components[Pickup]) == 200
    assert not esper._dead_entities
    assert grown < 16 * 1024, f"{grown} bytes kept after 120,000 entities came and went"
    app.close()
