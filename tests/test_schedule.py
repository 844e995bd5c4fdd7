import pytest

from atmos.app import App
from atmos.schedule import STAGES, Schedule, ScheduleError


def record(log, name):
    def system(app):
        log.append(name)
    system.__qualname__ = name
    return system


def test_stages_run_in_fixed_order():
    log = []
    app = App()
    for stage in reversed(STAGES):
        app.add_system(record(log, stage), stage)
    app.update(1 / 30)
    app.update(1 / 30)
    assert log == ["startup", "update", "simulate", "render", "last", "update", "simulate", "render", "last"]
    app.close()


def test_before_and_after_labels_order_systems_in_a_stage():
    log = []
    s = Schedule()
    s.add(record(log, "c"), "update", after="b")
    s.add(record(log, "a"), "update", before="b")
    s.add(record(log, "b"), "update")
    s.add(record(log, "z"), "update")
    s.run("update", None)
    assert log.index("a") < log.index("b") < log.index("c")
    assert log == ["a", "b", "c", "z"]


def test_registration_order_breaks_ties():
    log = []
    s = Schedule()
    for name in "pqrs":
        s.add(record(log, name), "render")
    s.run("render", None)
    assert log == list("pqrs")


def test_unknown_label_names_the_system():
    s = Schedule()
    s.add(record([], "wind"), "update", after="weather")
    with pytest.raises(ScheduleError, match=r"'wind'.*unknown label 'weather'"):
        s.build()


def test_cycle_names_the_systems():
    s = Schedule()
    s.add(record([], "a"), "update", after="c")
    s.add(record([], "b"), "update", after="a")
    s.add(record([], "c"), "update", after="b")
    with pytest.raises(ScheduleError) as info:
        s.build()
    message = str(info.value)
    assert "cycle" in message and all(n in message for n in "abc")


def test_cross_stage_label_is_an_error():
    s = Schedule()
    s.add(record([], "a"), "update")
    s.add(record([], "b"), "render", after="a")
    with pytest.raises(ScheduleError, match="inside one stage"):
        s.build()


def test_unknown_stage_and_duplicate_label():
    s = Schedule()
    with pytest.raises(ScheduleError, match="unknown stage 'physics'.*startup, update, simulate, render, last"):
        s.add(record([], "a"), "physics")
    s.add(record([], "a"), "update")
    with pytest.raises(ScheduleError, match="labelled 'a'"):
        s.add(record([], "a"), "render")


def test_schedule_errors_surface_at_startup():
    app = App()
    app.add_system(record([], "x"), "update", before="missing")
    with pytest.raises(ScheduleError, match="missing"):
        app.startup()
    app.close()
