"""The bad-input suite: every public constructor, setting, resource field and command-line argument
given wrong types, NaN, ±inf, zero, negative, out-of-range and wrong-shape values.

For each case: a ValueError that names the setting (``Class.field``) and what is allowed ("must ..."),
raised where the mistake is made (construction, ``configure``, assignment, insertion, parsing), and
nothing half-applied: the settings object is the one before, and the App renders the frame it
rendered before (same pixels, the render graph not recompiled).

The settings cases are generated from the settings classes' own checks
(:func:`atmos.checks.declared_rules`) for every ``CheckedSettings`` subclass found by walking
``atmos.plugins`` (and the core), so a new setting is covered the day it is added; the live cases
run on one small frozen App per plugin (the scenes of ``test_live_settings``).
"""
from __future__ import annotations

import dataclasses
import importlib
import math
import pkgutil
import re

import numpy as np
import pytest

import atmos.plugins
import atmos.render_core
from atmos.app import App
from atmos.checks import CheckedSettings, Rule, declared_rules
from atmos.cli import main, parser
from atmos.gpu import create_headless
from atmos.lighting import Sun
from atmos.plugin import Plugin
from atmos.render_core import CapturePass

from test_live_settings import SPECS, live_fields

NAN, INF = math.nan, math.inf
SIZE = (48, 30)


# -- discovery -----------------------------------------------------------------------------------
def _import_all():
    for info in pkgutil.walk_packages(atmos.plugins.__path__, "atmos.plugins."):
        importlib.import_module(info.name)


def _subclasses(cls):
    for sub in cls.__subclasses__():
        yield sub
        yield from _subclasses(sub)


_import_all()
SETTINGS = sorted({c for c in _subclasses(CheckedSettings) if c.__module__.startswith("atmos.")},
                  key=lambda c: c.__name__)
PLUGINS = sorted({c for c in _subclasses(Plugin) if c.__module__.startswith("atmos.")
                  and getattr(c, "settings_class", None) is not None}, key=lambda c: c.__name__)


# -- generated bad values ------------------------------------------------------------------------
def _beyond(bound: float, sign: int) -> float:
    return bound + sign * max(1.0, abs(bound))


def bad_values(rule: Rule | None) -> list[tuple[str, object]]:
    """(label, value) pairs the rule must refuse; without a rule (a field checked by hand) the generic
    wrong types."""
    if rule is None:
        return [("object", object()), ("nan", NAN), ("string", "no such value")]
    kind = rule.kind
    cases = [] if getattr(rule, "optional", False) else [("None", None)]
    if kind == "num":
        cases += [("string", "1.0"), ("bool", True), ("nan", NAN), ("+inf", INF), ("-inf", -INF), ("list", [1.0])]
        if rule.lo is not None:
            cases.append(("below", rule.lo if rule.lo_open else _beyond(rule.lo, -1)))
        if rule.hi is not None:
            cases.append(("above", _beyond(rule.hi, +1)))
    elif kind == "int":
        cases += [("float", 1.5), ("string", "3"), ("bool", True), ("nan", NAN), ("inf", INF),
                  ("below", rule.lo - 1), ("above", rule.hi + 1)]
    elif kind == "vec":
        n = rule.n
        cases += [("short", (1.0,) * (n - 1)), ("long", (1.0,) * (n + 1)), ("nan", (NAN,) * n), ("inf", (INF,) * n),
                  ("string", "abc"), ("scalar", 1.0)]
        if rule.vec_kind in ("positive", "non-negative"):
            cases.append(("negative", (-1.0,) * n))
        if rule.vec_kind == "positive":
            cases.append(("zero", (0.0,) * n))
        if rule.lo is not None:
            cases.append(("below", (rule.lo / 2 if rule.lo > 0 else _beyond(rule.lo, -1),) * n))
    elif kind == "bool":
        cases += [("int", 1), ("string", "yes")]
    elif kind == "choice":
        cases += [("unknown", f"no-such-{rule.choices[0]}"), ("int", 3)]
    elif kind == "shape":
        cases += [("zero", (0, 1, 1)), ("negative", (-1, 4, 4)), ("short", (4, 4)), ("float", (1.5, 4, 4)),
                  ("string", "abc")]
        if rule.hi is not None:
            cases.append(("above", (int(rule.hi) + 1, 4, 4)))
    else:
        raise AssertionError(f"no bad values for rules of kind {kind!r}: add them here")
    return cases


def field_value(default_settings, rule_name: str, value):
    """The field's value with ``value`` put where the rule looks (``resolutions[2]``: one item)."""
    field, _, index = rule_name.partition("[")
    if not index:
        return value
    items = list(getattr(default_settings, field))
    items[int(index.rstrip("]"))] = value
    return tuple(items)


def cases_of(cls) -> list[tuple[str, str, object]]:
    """(field, label, value) for every field of ``cls``: from its declared rules, generic ones otherwise."""
    rules = declared_rules(cls)
    default = cls()
    out = []
    for f in dataclasses.fields(cls):
        mine = [r for r in rules if r.field == f.name]
        for rule in mine or [None]:
            name = rule.name if rule is not None else f.name
            for label, value in bad_values(rule):
                out.append((f.name, f"{name}={label}", field_value(default, name, value)))
    return out


SETTING_CASES = [(cls, field, label, value) for cls in SETTINGS for field, label, value in cases_of(cls)]


def expect(error, owner: str, field: str) -> None:
    text = str(error.value)
    assert f"{owner}.{field}" in text and "must" in text, f"the error does not name {owner}.{field} " \
                                                          f"and what is allowed: {text}"


# -- settings: construction ----------------------------------------------------------------------
def test_every_settings_class_and_plugin_is_found():
    names = {c.__name__ for c in SETTINGS}
    assert {"RenderCoreSettings", "WeatherSettings", "CloudSettings", "FogSettings", "SkySettings"} <= names
    assert {p.settings_class for p in PLUGINS} <= set(SETTINGS)
    for cls in SETTINGS:
        assert cases_of(cls), f"{cls.__name__} has no generated cases"


@pytest.mark.parametrize("cls, field, label, value", SETTING_CASES,
                         ids=[f"{c.__name__}.{label}" for c, _, label, _ in SETTING_CASES])
def test_a_bad_setting_is_refused_at_construction_naming_it(cls, field, label, value):
    with pytest.raises(ValueError) as error:
        cls(**{field: value})
    expect(error, cls.__name__, field)


@pytest.mark.parametrize("plugin", PLUGINS, ids=[p.__name__ for p in PLUGINS])
def test_a_plugin_refuses_bad_settings_when_it_is_made(plugin):
    cls = plugin.settings_class
    field, label, value = cases_of(cls)[0]
    with pytest.raises(ValueError) as error:
        plugin(**{field: value})
    expect(error, cls.__name__, field)
    with pytest.raises(ValueError, match=f"unknown {cls.__name__} setting"):
        plugin(no_such_setting=1)


# -- settings: live, on one frozen App per plugin ------------------------------------------------
@pytest.fixture(scope="module")
def small_gpu():
    gpu = create_headless(SIZE)
    yield gpu
    gpu.release()                                   # closes the scenes' Apps too


_SCENES: dict = {}


def scene(gpu, name):
    """(app, plugin) of ``SPECS[name]``: built once, frozen (dt = 0, sliced jobs paused)."""
    if name not in _SCENES:
        spec = SPECS[name]
        app = App(gpu).add_plugins(*spec.make())
        app.graph.add_pass(CapturePass())
        app.insert_resource(Sun(np.array(spec.sun.direction), spec.sun.color))
        spec.camera(app)
        plugin = next(p for p in app.plugins if isinstance(p, spec.kind))
        app.run_frames(max(1, int(spec.warm / 0.25)), dt=0.25)
        for job in list(app.frames.jobs):
            app.frames.remove(job)
        if spec.before.get("__all__") is not None:
            spec.before["__all__"](app, plugin)
        _SCENES[name] = app, plugin
    return _SCENES[name]


def frame(app):
    app.update(0.0)
    assert app.gpu.ctx.error == "GL_NO_ERROR"
    capture = next(p for p in app.graph.passes if isinstance(p, CapturePass))
    return capture.color.copy(), app.gpu.read_pixels()


def owner_and_rule_cases(kind, dotted: str):
    """(owner class, cases) of a live field ``outer.inner`` or ``field`` of plugin ``kind``."""
    cls = kind.settings_class
    *outer, name = dotted.split(".")
    for part in outer:
        cls = type(getattr(cls(), part))
    return cls, [(label, value) for field, label, value in cases_of(cls) if field == name]


def nested(dotted: str, value) -> dict:
    outer, _, inner = dotted.partition(".")
    if not inner:
        return {outer: value}
    return {outer: nested(inner, value)}


LIVE_CASES = [(name, dotted) for name, spec in SPECS.items() for dotted in live_fields(spec.kind, nested=True)]


@pytest.mark.parametrize("name, dotted", LIVE_CASES, ids=[f"{n}.{d}" for n, d in LIVE_CASES])
def test_a_bad_live_change_is_refused_and_the_app_renders_as_before(small_gpu, name, dotted):
    app, plugin = scene(small_gpu, name)
    owner, cases = owner_and_rule_cases(type(plugin), dotted)
    shown = frame(app)
    compiled = app.graph.compile()
    settings = plugin.settings
    for label, value in cases:
        with pytest.raises(ValueError) as error:
            plugin.configure(**nested(dotted, value))
        expect(error, owner.__name__, dotted.rsplit(".", 1)[-1])
        assert plugin.settings is settings, f"{dotted}={label} changed the settings"
    again = frame(app)
    assert app.graph.compile() is compiled, "a refused change recompiled the render graph"
    assert np.array_equal(again[0], shown[0]) and np.array_equal(again[1], shown[1]), "a refused change showed"


BIG = 1e30


def extremes(rule: Rule) -> list[tuple[str, object]]:
    """The allowed values at the ends of a rule's range (1e30 where it has no bound)."""
    if rule.kind == "int":
        return [("max", rule.hi), ("min", rule.lo)]
    if rule.kind == "num":
        lo = -BIG if rule.lo is None else (rule.lo + max(1e-30, abs(rule.lo) * 1e-9) if rule.lo_open else rule.lo)
        return [("max", BIG if rule.hi is None else rule.hi), ("min", lo)]
    if rule.kind == "vec":
        lo = rule.lo if rule.lo is not None else {"positive": 1e-30, "non-negative": 0.0}.get(rule.vec_kind, -BIG)
        return [("max", (BIG,) * rule.n), ("min", (lo,) * rule.n)]
    return []


@pytest.mark.parametrize("name, dotted", LIVE_CASES, ids=[f"{n}.{d}" for n, d in LIVE_CASES])
def test_the_extremes_a_setting_allows_render_without_nan(small_gpu, name, dotted):
    """Every allowed value, the ends of each range included, renders a finite frame with no GL error
    (a value the other fields refuse beside it is refused by name, which is fine too)."""
    app, plugin = scene(small_gpu, name)
    owner, _ = owner_and_rule_cases(type(plugin), dotted)
    field = dotted.rsplit(".", 1)[-1]
    current = plugin.settings
    for part in dotted.split(".")[:-1]:
        current = getattr(current, part)
    try:
        for rule in [r for r in declared_rules(owner) if r.field == field]:
            for label, value in extremes(rule):
                try:
                    plugin.configure(**nested(dotted, field_value(current, rule.name, value)))
                except ValueError as error:                  # refused beside the other fields' values
                    assert f"{owner.__name__}." in str(error) and "must" in str(error), str(error)
                    continue
                color, _ = frame(app)
                assert np.isfinite(color).all(), f"{owner.__name__}.{rule.name} = {label} ({value}) renders NaN or inf"
    finally:
        plugin.configure(**nested(dotted, getattr(current, field)))


def test_every_effect_plugin_with_settings_has_a_live_scene():
    """Effects (atmos.plugins) are checked live on their test_live_settings scene; the rest by construction."""
    effects = {p for p in PLUGINS if p.__module__.startswith("atmos.plugins.")}
    missing = sorted(p.__name__ for p in effects - {spec.kind for spec in SPECS.values()})
    assert not missing, f"plugins without a live scene: {missing}; add a Spec to tests/test_live_settings.py SPECS"


ISSUE_CASES = [   # the settings issue 13 found unchecked (NaN or black frames without a word)
    ("render_core", dict(exposure=NAN), "RenderCoreSettings.exposure"),
    ("render_core", dict(exposure=-1.0), "RenderCoreSettings.exposure"),
    ("ground", dict(tile=0.0), "GroundSettings.tile"),
    ("ground", dict(tile=NAN), "GroundSettings.tile"),
    ("sky_gradient", dict(zenith=(NAN, 0.0, 0.0)), "SkyGradientSettings.zenith"),
    ("sky_gradient", dict(horizon=(-1.0, 0.0, 0.0)), "SkyGradientSettings.horizon"),
    ("terrain", dict(relief=NAN), "TerrainSettings.relief"),
    ("fog", dict(fog_color=(-0.5, 0.5, 0.5)), "FogSettings.fog_color must be 3 non-negative numbers"),
    ("clouds", dict(cell_size=(1e-30, 1e-30, 1e-30)), "CloudSettings.cell_size must be 3 positive numbers >= 0.001"),
    ("cloud_render", dict(size_factor=1e-30), "CloudRenderSettings.size_factor must be a finite number >= 0.001"),
]


@pytest.mark.parametrize("name, changes, message", ISSUE_CASES, ids=[f"{n}-{next(iter(c))}" for n, c, _ in ISSUE_CASES])
def test_the_settings_the_issue_found_unchecked_are_refused(small_gpu, name, changes, message):
    app, plugin = scene(small_gpu, name)
    shown = frame(app)
    with pytest.raises(ValueError, match=re.escape(message)):
        plugin.configure(**changes)
    assert np.array_equal(frame(app)[1], shown[1])


# -- resource fields and other public constructors -----------------------------------------------
def _sun_cases():
    cases = []
    for field in ("direction", "color", "ambient"):
        for label, value in bad_values(Rule("Sun", field, "vec", n=3, vec_kind="non-negative")):
            cases.append((field, label, value))
    cases.append(("direction", "zero", (0.0, 0.0, 0.0)))
    return [c for c in cases if not (c[0] == "direction" and c[1] == "negative")]   # any direction but 0


SUN_CASES = _sun_cases()


@pytest.mark.parametrize("field, label, value", SUN_CASES, ids=[f"{f}={l}" for f, l, _ in SUN_CASES])
def test_a_bad_sun_is_refused_when_made_and_when_assigned_and_the_frame_stays(small_gpu, field, label, value):
    with pytest.raises(ValueError) as error:
        Sun(**{field: value})
    expect(error, "Sun", field)
    app, _ = scene(small_gpu, "sky_gradient")
    sun = app.resource(Sun)
    shown = frame(app)
    before = getattr(sun, field)
    with pytest.raises(ValueError) as error:
        setattr(sun, field, value)
    expect(error, "Sun", field)
    assert np.array_equal(getattr(sun, field), before)
    assert np.array_equal(frame(app)[1], shown[1])


def _number_cases(lo=None, hi=None):
    return bad_values(Rule("", "", "num", lo=lo, hi=hi))


RESOURCE_CASES = (
    [("VolumeOrigin", f, label, v) for f in "xyz" for label, v in _number_cases()]
    + [("TimeOfDay", "hours", label, v) for label, v in _number_cases(0.0, 24.0)]
    + [("FrameScheduler", "slices_per_frame", label, v) for label, v in bad_values(Rule("", "", "int", lo=1, hi=10**6))]
    + [("FrameScheduler", "time_budget_ms", label, v) for label, v in _number_cases(0.0)
       if label != "None"] + [("FrameScheduler", "time_budget_ms", "zero", 0.0)]
    + [("FrameScheduler", "mode", label, v) for label, v in bad_values(Rule("", "", "choice", choices=("sliced",)))]
)


def _resource(kind):
    from atmos.slicing import FrameScheduler
    from atmos.plugins.daylight import TimeOfDay
    from atmos.plugins.clouds.weather import VolumeOrigin
    return {"VolumeOrigin": VolumeOrigin, "TimeOfDay": TimeOfDay, "FrameScheduler": FrameScheduler}[kind]()


@pytest.mark.parametrize("kind, field, label, value", RESOURCE_CASES,
                         ids=[f"{k}.{f}={l}" for k, f, l, _ in RESOURCE_CASES])
def test_a_bad_resource_field_is_refused_when_assigned(kind, field, label, value):
    resource = _resource(kind)
    before = getattr(resource, field)
    with pytest.raises(ValueError) as error:
        setattr(resource, field, value)
    expect(error, kind, field)
    assert getattr(resource, field) == before
    if kind != "FrameScheduler":
        with pytest.raises(ValueError):
            type(resource)(**{field: value})


def _ellipsoid_cases():
    from atmos.plugins.clouds.weather import MAX_CELLS, Ellipsoid
    cases = []
    for f in dataclasses.fields(Ellipsoid):
        cases += [(f.name, label, v) for label, v in (("nan", NAN), ("+inf", INF), ("-inf", -INF), ("string", "1"),
                                                      ("None", None), ("bool", True))]
        if f.name in ("rx", "ry", "rz", "lifetime"):
            cases += [(f.name, "zero", 0.0), (f.name, "negative", -1.0)]
        if f.name in ("x", "y", "z", "rx", "ry", "rz"):
            cases.append((f.name, "huge", 2 * MAX_CELLS))
    return cases


ELLIPSOID_CASES = _ellipsoid_cases()


@pytest.mark.parametrize("field, label, value", ELLIPSOID_CASES, ids=[f"{f}={l}" for f, l, _ in ELLIPSOID_CASES])
def test_add_ellipsoid_refuses_a_bad_ellipsoid_and_creates_nothing(field, label, value):
    from atmos.plugins.clouds.weather import Ellipsoid, add_ellipsoid
    from atmos.world import World
    world = World()
    with pytest.raises(ValueError) as error:
        add_ellipsoid(world, **{"x": 1.0, "lifetime": 10.0, field: value})
    expect(error, "Ellipsoid", field)
    assert world.get_component(Ellipsoid) == []
    world.close()


@pytest.mark.parametrize("bad", [dict(rx=INF), dict(ry=NAN), dict(yaw=NAN), dict(rz=0.0), dict(x=NAN),
                                 dict(lifetime=-1.0), dict(rx=1e39)], ids=lambda d: "-".join(f"{k}={v}" for k, v in d.items()))
def test_a_bad_ellipsoid_made_by_hand_is_skipped_with_one_warning_naming_it(small_gpu, bad):
    """Ellipsoid entities made without add_ellipsoid: the bad one is removed with one warning naming the
    entity; the others still form the region volume, in this frame and every later one."""
    from atmos.defaults import DefaultPlugins
    from atmos.plugins.ground import GroundPlugin
    from atmos.plugins.clouds.weather import (Ellipsoid, RegionVolume, WeatherPlugin, add_ellipsoid, ellipsoid_array,
                                       region_volume)
    weather = WeatherPlugin(volume_shape=(16, 8, 16), cloud_density=2, shrink_time=0.0)   # the good ones
    app = App(small_gpu).add_plugins(DefaultPlugins(overlay=False), GroundPlugin(), weather)
    good = [add_ellipsoid(app.world, x=4.0 + 4 * i, y=4.0, z=8.0, rx=3.0, ry=2.0, rz=3.0, lifetime=1e6) for i in range(2)]
    broken = app.world.create_entity(Ellipsoid(**{"x": 8.0, "y": 4.0, "z": 8.0, "rx": 3.0, "lifetime": 1e6, **bad}))
    with pytest.warns(RuntimeWarning) as caught:
        app.run_frames(2, dt=1 / 30)                 # one fixed step each
    assert len(caught) == 1 and f"ellipsoid entity {broken}" in str(caught[0].message)
    field = next(iter(bad))
    assert f"Ellipsoid.{field}" in str(caught[0].message)
    assert sorted(e for e, _ in app.world.get_component(Ellipsoid)) == good and weather.last_report.count == 2
    region = app.resource(RegionVolume)
    expected = region_volume(ellipsoid_array(app.world), (16, 8, 16))
    assert expected.max() > 0.5 and np.abs(region.download() - expected).max() < 1e-5, "the good ones form the region"
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        app.run_frames(3, dt=1 / 30)                 # later frames: no error, no warning
    app.close()


CONSTRUCTOR_CASES = [
    ("App gpu", lambda: App("gpu"), r"App gpu must be an atmos GpuContext"),
    ("App fixed_step", lambda: App(fixed_step=0.0), r"FixedClock\.step must be a finite number > 0"),
    ("App fixed_step", lambda: App(fixed_step="x"), r"FixedClock\.step must be"),
    ("App max_frame_dt", lambda: App(max_frame_dt=INF), r"FixedClock\.max_frame_dt must be"),
    ("App.update frame_dt", lambda: App().update(NAN), r"App\.update\.frame_dt must be a finite number >= 0"),
    ("App.update frame_dt", lambda: App().update(-1.0), r"App\.update\.frame_dt must be"),
    ("App.update frame_dt", lambda: App().update("x"), r"App\.update\.frame_dt must be"),
    ("App.run_frames n", lambda: App().run_frames(-1), r"App\.run_frames\.n must be a whole number"),
    ("App.run_frames n", lambda: App().run_frames(1.5), r"App\.run_frames\.n must be a whole number"),
    ("App.run_frames dt", lambda: App().run_frames(2, dt=INF), r"App\.run_frames\.dt must be"),
    ("add_system func", lambda: App().add_system(1), r"a system must be a callable func\(app\), got int"),
    ("add_system stage", lambda: App().add_system(print, "later"), r"unknown stage 'later'.*stages are startup"),
    ("add_system label", lambda: App().add_system(print, label=3), r"label must be a non-empty string or None"),
    ("add_system before", lambda: App().add_system(print, before=5), r"before must be a label or a list of labels"),
    ("add_system after", lambda: App().add_system(print, after=[None]), r"after must be a label or a list of labels"),
    ("insert_resource", lambda: App().insert_resource(None), r"insert_resource takes an object"),
    ("insert_resource", lambda: App().insert_resource(Sun), r"insert_resource takes an object .*did you mean Sun\(\)"),
    ("add_plugins", lambda: App().add_plugins(Sun()), r"add_plugins takes Plugin or PluginGroup instances, not Sun"),
    ("create_headless size", lambda: create_headless((NAN, 4)), r"size must be \(width, height\), two whole numbers"),
    ("create_headless size", lambda: create_headless("big"), r"size must be \(width, height\)"),
    ("create_headless size", lambda: create_headless((-5, 4)), r"size must be \(width, height\)"),
    ("create_headless size", lambda: create_headless((10**9, 4)), r"two whole numbers 0\.\.\d+"),
    ("create_headless backend", lambda: create_headless((4, 4), backend=3), r"backend must be a glcontext backend"),
    ("SliceTask name", lambda: _slice_task(3), r"a task name must be a non-empty string"),
    ("SliceTask run", lambda: _slice_task("t", run=3), r"run must be callable as run\(slice_index, job_ctx\)"),
    ("SliceTask slices", lambda: _slice_task("t", slices=-1), r"slices must be an int >= 0"),
    ("TextureDesc size", lambda: _desc((NAN, 4)), r"TextureDesc\.size must be"),
    ("TextureDesc components", lambda: _desc((4, 4), components=7), r"TextureDesc\.components must be 1, 2, 3 or 4"),
    ("TextureDesc dtype", lambda: _desc((4, 4), dtype="f8"), r"TextureDesc\.dtype must be one of"),
    ("FrameWriter fps", lambda: _writer(fps=0.0), r"FrameWriter\.fps must be a finite number > 0"),
    ("FrameWriter fps", lambda: _writer(fps=NAN), r"FrameWriter\.fps must be"),
    ("WeatherPlugin seed", lambda: _plugin("clouds.weather", "WeatherPlugin", seed=-1), r"WeatherPlugin\.seed must be"),
    ("WeatherPlugin dtype", lambda: _plugin("clouds.weather", "WeatherPlugin", dtype="f8"), r"WeatherPlugin\.dtype must be"),
    ("CloudsPlugin seed", lambda: _plugin("clouds", "CloudsPlugin", seed=1.5), r"CloudsPlugin\.seed must be"),
    ("CloudsPlugin warmup_steps", lambda: _plugin("clouds", "CloudsPlugin", warmup_steps=-1),
     r"CloudsPlugin\.warmup_steps must be"),
]


def _slice_task(name, slices=1, run=lambda index, job: None):
    from atmos.slicing import SliceTask
    return SliceTask(name, slices, run)


def _desc(*args, **kwargs):
    from atmos.graph import TextureDesc
    return TextureDesc(*args, **kwargs)


def _writer(**kwargs):
    import tempfile
    from atmos.output import FrameWriter
    return FrameWriter(tempfile.mkdtemp() + "/x.png", **kwargs)


def _plugin(module, name, **kwargs):
    return getattr(importlib.import_module(f"atmos.plugins.{module}"), name)(**kwargs)


@pytest.mark.parametrize("what, make, message", CONSTRUCTOR_CASES, ids=[f"{w}-{i}" for i, (w, _, _) in
                                                                        enumerate(CONSTRUCTOR_CASES)])
def test_a_bad_constructor_or_method_argument_is_a_clear_error(what, make, message):
    with pytest.raises((ValueError, TypeError)) as error:
        make()
    assert error.type is not TypeError or "add_plugins" in what, f"{what}: a bare TypeError: {error.value}"
    assert re.search(message, str(error.value)), str(error.value)


def test_a_bad_frame_size_is_refused_and_the_frame_stays(small_gpu):
    app, _ = scene(small_gpu, "ground")
    shown = frame(app)
    for size in [(NAN, 4), (10**9, 4), (-1, 4), (4,), "4x4", (4.5, 4)]:
        with pytest.raises(ValueError, match=r"GpuContext size must be \(width, height\)"):
            small_gpu.resize(size)
    assert small_gpu.size == SIZE and np.array_equal(frame(app)[1], shown[1])


# -- the command line: every argument of every subcommand ----------------------------------------
def _subcommands():
    top = parser()
    return next(a for a in top._actions if a.__class__.__name__ == "_SubParsersAction").choices


def _options():
    """(subcommand, option) for every option of every subcommand that takes a value."""
    return [(command, action.option_strings[-1]) for command, sub in _subcommands().items() for action in sub._actions
            if action.option_strings and action.nargs != 0 and action.type is not None]


def _positionals(command) -> list[str]:
    """A valid value for each positional argument of ``command`` (a demo name, or a game file name)."""
    return ["testbed" for a in _subcommands()[command]._actions if not a.option_strings]


CLI_VALUES = ["", " ", "nan", "inf", "-1", "0", "1.5", "x", "1e3", "99999999999999999999", "0x0", "7x", "-2x3"]
CLI_CASES = [(c, o, v) for c, o in _options() for v in CLI_VALUES]


@pytest.mark.parametrize("command, option, value", CLI_CASES, ids=[f"{c}{o}={v!r}" for c, o, v in CLI_CASES])
def test_every_command_line_value_is_accepted_or_refused_by_name(capsys, command, option, value):
    """Parsing only: a value is accepted, or refused with exit status 2 and a message naming the
    argument (no traceback, nothing rendered)."""
    argv = [command, *_positionals(command), f"{option}={value}"]
    try:
        parser().parse_args(argv)
    except SystemExit as exit_:
        err = capsys.readouterr().err
        assert exit_.code == 2 and f"argument {option}" in err and "Traceback" not in err, err


@pytest.mark.parametrize("argv, message", [
    (["demo", "testbed", "--out", ""], "argument --out: give FILE.mp4"),
    (["demo", "testbed", "--out", "x.mp4/"], "ends with '/' (a folder) but names a .mp4 file"),
    (["demo", "testbed", "--size=-2x3"], "width and height must be between 1 and 16384"),
    (["demo", "testbed", "--size", "16385x10"], "between 1 and 16384"),
    (["demo", "testbed", "--frames", "-1"], "give 1 or more"),
    (["demo", "testbed", "--seed", "4294967296"], "seeds are 0 .. 4294967295"),
    (["demo", "testbed", "--seed", "nan"], "is not an integer seed"),
    (["demo", "_cloudscape"], "unknown demo '_cloudscape'"),
    (["nosuch"], "invalid choice: 'nosuch'"),
])
def test_bad_command_lines_exit_2_with_a_message(capsys, argv, message):
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and message in err and "Traceback" not in err, err


def test_a_bad_environment_setting_of_a_demo_is_a_message_not_a_traceback(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("ATMOS_FOG_PRESET", "fig99")
    code = main(["demo", "fog_valley", "--headless", "--frames", "1", "--size", "32x18", "--quiet",
                 "--out", str(tmp_path / "x.png")])
    err = capsys.readouterr().err
    assert code == 1 and "atmos: unknown fog preset 'fig99'; allowed: valley, fig6" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
