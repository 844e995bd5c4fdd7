"""The one validation module: checks whose ValueErrors name ``Class.field``, what was given and what
is allowed (also the libraries' input checks, e.g. ``check_sun_dir``: a direction toward the sun),
and the settings convention every plugin follows.

The convention
--------------
* A plugin's settings are ONE frozen dataclass ``<Thing>Settings(CheckedSettings)``; each field is
  declared once, with its rule and its doc: ``steps: int = int_field(24, 1, 256, "samples per ray")``
  (:func:`num_field`, :func:`int_field`, :func:`vec_field`, :func:`bool_field`, :func:`choice_field`,
  :func:`nested_field`). ``CheckedSettings.__post_init__`` runs each field's check (the ``check_*``
  functions here) and keeps the normalised values; the class docstring gets a line per field (its
  default, what it allows, its doc). A class with rules across fields adds them in its own
  ``__post_init__`` after ``super().__post_init__()``.
* The plugin names it in ``settings_class`` and keeps it as ``plugin.settings``;
  ``Plugin(settings=None, **fields)`` builds it with :func:`plugin_settings` (the fields on top of
  ``settings`` or the defaults) and ``plugin.configure(**changes)`` swaps in what
  :func:`configure_settings` returns (all changes checked together; on any error nothing changes).
* Fields listed in the settings class's ``FIXED`` size what the plugin makes once (GPU buffers,
  a sliced job): ``configure`` refuses to change them, naming them; give them when making the plugin.
* Passes and systems read ``plugin.settings`` every frame, so a change shows on the next frame.

:func:`declared_rules` lists the checks a settings class runs on its fields (the allowed values it
declares): the bad-input tests generate their cases from them, so a new field is covered the day
it is added.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
import operator
from dataclasses import dataclass
from typing import ClassVar

import numpy as np


@dataclass(frozen=True)
class Rule:
    """One check as a settings class runs it: ``kind`` names the check (``num``, ``int``, ``vec``,
    ``bool``, ``choice``, ``shape``), the other fields are its arguments (which values it allows)."""
    owner: str
    name: str                  # the field, or e.g. "resolutions[0]" for one item of it
    kind: str
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False      # num: lo itself is refused
    optional: bool = False
    n: int = 0                 # vec: how many numbers (each >= lo when lo is given)
    vec_kind: str = "finite"   # vec: 'finite', 'positive' or 'non-negative'
    choices: tuple = ()

    @property
    def field(self) -> str:
        """The dataclass field the rule checks."""
        return self.name.split("[", 1)[0]


_recording: list | None = None


def _declare(owner: str, name: str, kind: str, **args) -> None:
    if _recording is not None:
        _recording.append(Rule(owner, name, kind, **args))


def declared_rules(cls) -> list[Rule]:
    """The :class:`Rule` of every check ``cls()`` runs on its own fields (its ``__post_init__`` on the
    defaults, recorded): what each field allows. Checks that run only for other values of other
    fields are not seen; fields checked by hand have no rule. Not thread-safe."""
    global _recording
    saved, _recording = _recording, []
    try:
        cls()
        return [rule for rule in _recording if rule.owner == cls.__name__]
    finally:
        _recording = saved


def check_vec(owner: str, name: str, value, n: int, kind: str = "finite", optional: bool = False,
              lo: float | None = None) -> tuple | None:
    """``n`` finite floats; ``kind`` 'positive' or 'non-negative' narrows them, ``lo`` (each >= lo)
    too; ``optional``: None passes."""
    if _recording is not None:
        _declare(owner, name, "vec", n=n, vec_kind=kind, optional=optional, lo=lo)
    if optional and value is None:
        return None
    ok = (type(value) is tuple or type(value) is list) and len(value) == n
    if ok:                              # the common case: finite floats already (x - x is 0 only for those)
        for x in value:
            if (type(x) is not float and type(x) is not np.float64) or x - x != 0.0:
                ok = False
                break
    if ok:
        v = tuple(map(float, value))
    else:
        try:
            v = () if isinstance(value, (str, bytes)) else tuple(_real(x) for x in value)
        except TypeError:
            v = ()
        ok = len(v) == n and all(math.isfinite(x) for x in v)
    if ok and kind == "positive":
        ok = min(v) > 0
    elif ok and kind == "non-negative":
        ok = min(v) >= 0
    if ok and lo is not None:
        ok = min(v) >= lo
    if not ok:
        floor = f" >= {lo}" if lo is not None else ""
        raise ValueError(f"{owner}.{name} must be {n} {kind} numbers{floor}{' or None' if optional else ''}, "
                         f"got {value!r}")
    return v


def _real(value) -> float:
    """``value`` as a float; NaN for what is not a real number (strings and bools included)."""
    if isinstance(value, (str, bytes, bool, np.bool_)):
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def check_num(owner: str, name: str, value, lo: float | None = None, hi: float | None = None,
              lo_open: bool = False, optional: bool = False) -> float | None:
    """A finite float within [lo, hi] (``lo_open``: strictly above lo); ``optional``: None passes."""
    if _recording is not None:
        _declare(owner, name, "num", lo=lo, hi=hi, lo_open=lo_open, optional=optional)
    if optional and value is None:
        return None
    v = value if type(value) is float else _real(value)
    ok = v - v == 0.0 and (lo is None or (v > lo if lo_open else v >= lo)) and (hi is None or v <= hi)
    if not ok:
        bounds = [t for t in ("" if lo is None else f"{'>' if lo_open else '>='} {lo}",
                              "" if hi is None else f"<= {hi}") if t]
        raise ValueError(f"{owner}.{name} must be a finite number{' ' + ' and '.join(bounds) if bounds else ''}"
                         f"{' or None' if optional else ''}, got {value!r}")
    return v


def check_int(owner: str, name: str, value, lo: int, hi: int) -> int:
    """A whole number in lo..hi (bools are refused)."""
    _declare(owner, name, "int", lo=lo, hi=hi)
    try:
        v = None if isinstance(value, (bool, np.bool_)) else operator.index(value)
    except TypeError:
        v = None
    if v is None or not lo <= v <= hi:
        raise ValueError(f"{owner}.{name} must be a whole number {lo}..{hi}, got {value!r}")
    return int(v)


def check_bool(owner: str, name: str, value) -> bool:
    """True or False (numpy bools too; not 0/1 or strings)."""
    _declare(owner, name, "bool")
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{owner}.{name} must be True or False, got {value!r}")
    return bool(value)


def check_choice(owner: str, name: str, value, choices) -> str:
    """One of the strings ``choices``."""
    _declare(owner, name, "choice", choices=tuple(choices))
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"{owner}.{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def is_int(value) -> bool:
    """True for Python and numpy integers, not bools."""
    return isinstance(value, (numbers.Integral, np.integer)) and not isinstance(value, (bool, np.bool_))


def check_shape(shape, name: str = "shape", hi: int | None = None, optional: bool = False) -> tuple[int, int, int] | None:
    """``(nx, ny, nz)`` as ints; ValueError naming ``name`` unless three positive ints (each at most
    ``hi`` when given); ``optional``: None passes."""
    owner, _, field = name.rpartition(".")
    _declare(owner, field, "shape", hi=hi, optional=optional)
    if optional and shape is None:
        return None
    try:
        values = None if isinstance(shape, (str, bytes)) else tuple(shape)
    except TypeError:
        values = None
    if values is None or len(values) != 3 or not all(is_int(n) and 1 <= n <= (hi or n) for n in values):
        allowed = "positive ints" if hi is None else f"ints in [1, {hi}]"
        raise ValueError(f"{name} must be {'None or ' if optional else ''}three {allowed} (nx, ny, nz), got {shape!r}")
    return tuple(int(n) for n in values)


def check_sun_dir(sun_dir, name: str = "sun_dir") -> np.ndarray:
    """The unit float64 direction toward the sun, or a ValueError naming ``name`` (allowed: a finite
    3-vector, length > 0)."""
    try:
        d = None if isinstance(sun_dir, (str, bytes)) else np.asarray(sun_dir, dtype=np.float64)
    except (TypeError, ValueError):
        d = None
    if d is None or d.shape != (3,):
        raise ValueError(f"{name} must be a 3-vector (x, y, z) pointing toward the sun; got {sun_dir!r}")
    if not np.isfinite(d).all():
        raise ValueError(f"{name} must be finite; got {tuple(d)}")
    big = np.abs(d).max()
    if big == 0:
        raise ValueError(f"{name} must have a length > 0; got the zero vector")
    d = d / big
    return d / math.sqrt(d.dot(d))   # np.linalg.norm's own formula (1-D float64), without its overhead


def check_known(owner: str, changes: dict, known) -> None:
    """Refuse names that are not settings of ``owner``."""
    unknown = sorted(set(changes) - set(known))
    if unknown:
        raise ValueError(f"unknown {owner} setting(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")


def _field(default, doc: str, check, **args):
    return dataclasses.field(default=default, metadata={"check": (check, args), "doc": doc})


def num_field(default, lo: float | None = None, hi: float | None = None, doc: str = "", *, lo_open: bool = False,
              optional: bool = False):
    """A field holding a finite number in [lo, hi] (:func:`check_num`)."""
    return _field(default, doc, check_num, lo=lo, hi=hi, lo_open=lo_open, optional=optional)


def int_field(default, lo: int, hi: int, doc: str = ""):
    """A field holding a whole number in lo..hi (:func:`check_int`)."""
    return _field(default, doc, check_int, lo=lo, hi=hi)


def vec_field(default, n: int, kind: str = "finite", doc: str = "", *, lo: float | None = None,
              optional: bool = False):
    """A field holding ``n`` numbers (:func:`check_vec`)."""
    return _field(default, doc, check_vec, n=n, kind=kind, lo=lo, optional=optional)


def bool_field(default: bool, doc: str = ""):
    """A field holding True or False (:func:`check_bool`)."""
    return _field(default, doc, check_bool)


def choice_field(default: str, choices, doc: str = ""):
    """A field holding one of the strings ``choices`` (:func:`check_choice`)."""
    return _field(default, doc, check_choice, choices=tuple(choices))


def nested_field(default, doc: str = ""):
    """A field holding settings of their own (a CheckedSettings of ``default``'s type); ``replace``
    takes a dict of changes to them."""
    return _field(default, doc, check_type, cls=type(default))


def type_field(default, cls, doc: str = "", *, optional: bool = False):
    """A field holding an instance of ``cls`` (or None when ``optional``; :func:`check_type`)."""
    return _field(default, doc, check_type, cls=cls, optional=optional)


def check_type(owner: str, name: str, value, cls, optional: bool = False):
    """An instance of ``cls`` (or None when ``optional``)."""
    if value is None and optional:
        return None
    if not isinstance(value, cls):
        article = "an" if cls.__name__[0] in "AEIOU" else "a"
        raise ValueError(f"{owner}.{name} must be {article} {cls.__name__}, got {type(value).__name__}")
    return value


def _allowed(check, args) -> str:
    if check is check_num:
        bounds = [t for t in ("" if args["lo"] is None else f"{'>' if args['lo_open'] else '>='} {args['lo']}",
                              "" if args["hi"] is None else f"<= {args['hi']}") if t]
        return " and ".join(bounds) or "any finite number"
    if check is check_int:
        return f"{args['lo']}..{args['hi']}"
    if check is check_vec:
        return f"{args['n']} {args['kind']} numbers" + (f" >= {args['lo']}" if args["lo"] is not None else "")
    if check is check_bool:
        return "True or False"
    if check is check_choice:
        return " | ".join(map(repr, args["choices"]))
    return f"a {args['cls'].__name__}"


class CheckedSettings:
    """Base of every plugin's frozen settings dataclass: its ``__post_init__`` runs the rule declared on
    each field (module docstring).

    ``FIXED``: names of the fields that cannot change while the plugin runs (they size what it makes
    once); :func:`configure_settings` refuses them.
    """

    FIXED: ClassVar[tuple[str, ...]] = ()

    def __init_subclass__(cls, **kwargs):
        """Append a line per declared field to the class docstring: its default, what it allows, its doc."""
        super().__init_subclass__(**kwargs)
        lines = []
        for name in cls.__dict__.get("__annotations__", {}):
            f = cls.__dict__.get(name)
            if isinstance(f, dataclasses.Field) and "check" in f.metadata:
                check, args = f.metadata["check"]
                none = " or None" if args.get("optional") else ""
                fixed = ", fixed" if name in cls.FIXED else ""
                default = repr(f.default)
                if isinstance(f.default, CheckedSettings) and len(default) > 60:
                    default = f"{type(f.default).__name__}()"
                lines.append(f"    ``{name}`` = {default} ({_allowed(check, args)}{none}{fixed}): {f.metadata['doc']}")
        if lines:
            cls.__doc__ = (cls.__doc__ or "").rstrip() + "\n\n    Fields:\n\n" + "\n".join(lines) + "\n"

    def __post_init__(self):
        owner = type(self).__name__
        checked = {}
        for f in dataclasses.fields(self):
            if "check" in f.metadata:
                check, args = f.metadata["check"]
                checked[f.name] = check(owner, f.name, getattr(self, f.name), **args)
        self.store(checked)

    def replace(self, **changes):
        """A checked copy with ``changes``; unknown names and bad values raise ValueError. A field
        holding nested settings takes a dict of changes to them (``weather={"cloud_density": 5}``)."""
        check_known(type(self).__name__, changes, [f.name for f in dataclasses.fields(self)])
        for name, value in changes.items():
            current = getattr(self, name)
            if isinstance(value, dict) and isinstance(current, CheckedSettings):
                changes[name] = current.replace(**value)
        return dataclasses.replace(self, **changes)

    def store(self, checked: dict) -> None:
        """For ``__post_init__``: keep the checked, normalised values (the dataclass is frozen)."""
        for name, value in checked.items():
            object.__setattr__(self, name, value)


def _same(a, b) -> bool:
    try:
        return bool(a is b or a == b)
    except (TypeError, ValueError):          # arrays compare elementwise
        return bool(np.array_equal(a, b))


def plugin_settings(plugin: str, cls, settings, fields: dict):
    """A plugin's settings at construction: ``settings`` (a ``cls``, or None for the defaults) with
    keyword ``fields`` applied on top, all checked before anything is kept."""
    if settings is not None and not isinstance(settings, cls):
        raise ValueError(f"{plugin} settings must be a {cls.__name__}, got {type(settings).__name__}")
    base = settings if settings is not None else cls()
    return base.replace(**fields) if fields else base


def configure_settings(plugin: str, current, changes: dict):
    """A plugin's settings after a live change: ``current.replace(**changes)`` (unknown names and
    bad values refused, all together), refusing changes of ``FIXED`` fields; ``current`` is untouched."""
    new = current.replace(**changes)
    fixed = _fixed_changes(current, new)
    if fixed:
        raise ValueError(f"{', '.join(fixed)} cannot change while {plugin} runs (fixed settings size what it "
                         f"makes once; give them when making the plugin)")
    return new


def _fixed_changes(old, new, prefix: str = "") -> list[str]:
    """``Class.field`` of every FIXED field that differs between ``old`` and ``new``, nested settings too."""
    found = []
    owner = prefix or type(old).__name__
    for f in dataclasses.fields(old):
        a, b = getattr(old, f.name), getattr(new, f.name)
        if f.name in type(old).FIXED and not _same(a, b):
            found.append(f"{owner}.{f.name}")
        elif isinstance(a, CheckedSettings) and isinstance(b, CheckedSettings) and a is not b:
            found += _fixed_changes(a, b, f"{owner}.{f.name}")
    return found
