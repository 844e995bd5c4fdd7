from dataclasses import dataclass

import pytest

from atmos.app import App
from atmos.plugin import Plugin, PluginGroup, discover_plugins


@dataclass(slots=True)
class Position:
    x: float = 0.0


@dataclass(slots=True)
class Velocity:
    v: float = 1.0


def move(app):
    for _, (p, v) in app.world.get_components(Position, Velocity):
        p.x += v.v


def test_two_apps_never_share_entities():
    a, b = App(), App()
    a.world.create_entity(Position(), Velocity())
    a.world.create_entity(Position(), Velocity())
    b.world.create_entity(Position())
    a.add_system(move, label="move")
    b.add_system(move, label="move")
    a.run_frames(3)
    b.run_frames(3)
    assert a.world.entity_count() == 2 and b.world.entity_count() == 1
    assert [p.x for _, p in a.world.get_component(Position)] == [3.0, 3.0]
    assert [p.x for _, p in b.world.get_component(Position)] == [0.0]
    a.close()
    assert b.world.entity_count() == 1
    b.close()


class Counter(Plugin):
    def __init__(self, log):
        self.log = log

    def build(self, app):
        self.log.append(("build", self.name))

    def finish(self, app):
        self.log.append(("finish", self.name))

    def cleanup(self, app):
        self.log.append(("cleanup", self.name))


class First(Counter):
    pass


class Second(Counter):
    pass


class Third(Counter):
    pass


def test_plugin_lifecycle_and_group_editing():
    log = []
    group = PluginGroup(First(log), Third(log)).add_before(Third, Second(log))
    app = App().add_plugins(group)
    app.startup()
    app.close()
    assert log == [("build", "First"), ("build", "Second"), ("build", "Third"),
                   ("finish", "First"), ("finish", "Second"), ("finish", "Third"),
                   ("cleanup", "Third"), ("cleanup", "Second"), ("cleanup", "First")]


def test_group_disable_and_errors():
    log = []
    group = PluginGroup(First(log), Second(log)).disable(First)
    assert [p.name for p in group] == ["Second"]
    with pytest.raises(ValueError, match="Third is not in PluginGroup; it holds: Second"):
        group.disable(Third)
    app = App()
    app.add_plugins(First(log))
    with pytest.raises(ValueError, match="First was added twice"):
        app.add_plugins(First(log))
    with pytest.raises(TypeError, match="Plugin or PluginGroup"):
        app.add_plugins(object())
    app.close()


def test_missing_resource_is_a_clear_error():
    app = App()
    with pytest.raises(KeyError, match="no Position resource"):
        app.resource(Position)
    app.close()


def test_init_resource_makes_one_and_then_keeps_it():
    app = App()
    made = app.init_resource(Position)
    assert isinstance(made, Position) and app.resource(Position) is made
    made.x = 5.0
    assert app.init_resource(Position) is made and made.x == 5.0, "an existing resource is kept as it is"
    app.close()


def test_entry_point_discovery_finds_the_shipped_plugins():
    found = discover_plugins()
    assert {"ground", "sky_gradient", "overlay", "clouds", "cloud_render", "weather"} <= set(found)
    assert "template_volume" not in found, "the testbed's template volume is not a shipped effect"
    assert all(issubclass(cls, Plugin) for cls in found.values())


class Counts(Plugin):
    """Adds a system and a resource, so what a failed call leaves behind shows."""

    def build(self, app):
        app.add_system(lambda app: None, label=f"count_{id(self)}")
        app.insert_resource(self)


class Refuses(Plugin):
    def build(self, app):
        raise ValueError("refused on purpose")


def test_one_add_plugins_call_is_all_or_nothing():
    app = App()
    systems = len(app.schedule.systems)
    with pytest.raises(ValueError, match="refused on purpose"):
        app.add_plugins(Counts(), Refuses())
    assert app.plugins == [] and len(app.schedule.systems) == systems and Counts not in app.resources
    with pytest.raises(ValueError, match="added twice"):
        app.add_plugins(Counts(), Counts())                   # the second is refused: the first goes too
    assert app.plugins == []
    app.add_plugins(Counts())                                 # a corrected call works
    assert len(app.plugins) == 1
    app.close()


def test_a_plugin_belongs_to_one_app_and_an_app_without_a_gpu_says_what_it_needs():
    first, second = App(), App()
    plugin = Counts()
    first.add_plugins(plugin)
    with pytest.raises(ValueError, match="this Counts belongs to another App that is still open"):
        second.add_plugins(plugin)
    assert second.plugins == []
    from atmos.plugins.sky import SkyPlugin
    from atmos.app import AppError
    with pytest.raises(AppError, match=r"SkyPlugin draws with the GPU and this App has none.*create_headless"):
        second.add_plugins(SkyPlugin())
    assert second.plugins == []
    first.close()
    second.add_plugins(plugin)                                # the first App closed: the plugin is free
    assert second.plugins == [plugin]
    second.close()


def test_default_plugins_hide_the_frame_time_overlay_until_asked():
    from atmos.defaults import DefaultPlugins
    from atmos.overlay import OverlayPlugin
    assert DefaultPlugins().get(OverlayPlugin).settings.visible is False
    assert DefaultPlugins(overlay=True).get(OverlayPlugin).settings.visible is True
