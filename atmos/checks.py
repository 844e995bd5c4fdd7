"""The one validation module: checks whose ValueErrors name ``Class.field``, what was given and what
is allowed (also the libraries' input checks, e.g. ``check_sun_dir``: a direction toward the sun),
and the settings convention every plugin follows.

The convention
--------------
* A plugin's settings are ONE frozen dataclass ``<Thing>Settings(CheckedSettings)`` whose
  ``__post_init__`` checks every field with the ``check_*`` functions here (and keeps the
  normalised values with :meth:`CheckedSettings.store`).
* The plugin names it in ``settings_class`` and keeps it as ``plugin.settings``;
  ``Plugin(settings=None, **fields)`` builds it with :func:`plugin_settings` (the fields on top of
  ``settings`` or the defaults) and ``plugin.configure(**changes)`` swaps in what
  :func:`configure_settings` returns (all changes checked together; on any error nothing changes).
* Fields listed in the settings class's ``FIXED`` size what the plugin makes once (GPU buffers,
  a sliced job): ``configure`` refuses to change them, naming them; give them when making the plugin.
* Passes and systems read ``plugin.settings`` every frame, so a change shows on the next frame.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
import operator
from typing import ClassVar

import numpy as np


def check_vec(owner: str, name: str, value, n: int, kind: str = "finite", optional: bool = False) -> tuple | None:
    """``n`` finite floats; ``kind`` 'positive' or 'non-negative' narrows them; ``optional``: None passes."""
    if optional and value is None:
        return None
    try:
        v = () if isinstance(value, (str, bytes)) else tuple(_real(x) for x in value)
    except TypeError:
        v = ()
    ok = len(v) == n and all(math.isfinite(x) for x in v)
    if ok and kind == "positive":
        ok = min(v) > 0
    elif ok and kind == "non-negative":
        ok = min(v) >= 0
    if not ok:
        raise ValueError(f"{owner}.{name} must be {n} {kind} numbers{' or None' if optional else ''}, got {value!r}")
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
    if optional and value is None:
        return None
    v = _real(value)
    ok = math.isfinite(v) and (lo is None or (v > lo if lo_open else v >= lo)) and (hi is None or v <= hi)
    if not ok:
        bounds = [t for t in ("" if lo is None else f"{'>' if lo_open else '>='} {lo}",
                              "" if hi is None else f"<= {hi}") if t]
        raise ValueError(f"{owner}.{name} must be a finite number{' ' + ' and '.join(bounds) if bounds else ''}"
                         f"{' or None' if optional else ''}, got {value!r}")
    return v


def check_int(owner: str, name: str, value, lo: int, hi: int) -> int:
    """A whole number in lo..hi (bools are refused)."""
    try:
        v = None if isinstance(value, (bool, np.bool_)) else operator.index(value)
    except TypeError:
        v = None
    if v is None or not lo <= v <= hi:
        raise ValueError(f"{owner}.{name} must be a whole number {lo}..{hi}, got {value!r}")
    return int(v)


def check_bool(owner: str, name: str, value) -> bool:
    """True or False (numpy bools too; not 0/1 or strings)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{owner}.{name} must be True or False, got {value!r}")
    return bool(value)


def check_choice(owner: str, name: str, value, choices) -> str:
    """One of the strings ``choices``."""
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"{owner}.{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def is_int(value) -> bool:
    """True for Python and numpy integers, not bools."""
    return isinstance(value, (numbers.Integral, np.integer)) and not isinstance(value, (bool, np.bool_))


def check_shape(shape, name: str = "shape") -> tuple[int, int, int]:
    """``(nx, ny, nz)`` as ints; ValueError naming ``name`` unless three positive ints."""
    try:
        values = tuple(shape)
    except TypeError:
        values = None
    if values is None or len(values) != 3 or not all(is_int(n) and n >= 1 for n in values):
        raise ValueError(f"{name} must be three positive ints (nx, ny, nz), got {shape!r}")
    return tuple(int(n) for n in values)


def check_sun_dir(sun_dir) -> np.ndarray:
    """The unit float64 direction toward the sun, or a ValueError (allowed: a finite 3-vector, length > 0)."""
    try:
        d = np.asarray(sun_dir, dtype=np.float64)
    except (TypeError, ValueError):
        d = None
    if d is None or d.shape != (3,):
        raise ValueError(f"sun_dir must be a 3-vector (x, y, z) pointing toward the sun; got {sun_dir!r}")
    if not np.isfinite(d).all():
        raise ValueError(f"sun_dir must be finite; got {tuple(d)}")
    big = np.abs(d).max()
    if big == 0:
        raise ValueError("sun_dir must have a length > 0; got the zero vector")
    d = d / big
    return d / np.linalg.norm(d)


def check_known(owner: str, changes: dict, known) -> None:
    """Refuse names that are not settings of ``owner``."""
    unknown = sorted(set(changes) - set(known))
    if unknown:
        raise ValueError(f"unknown {owner} setting(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")


class CheckedSettings:
    """Base of every plugin's frozen settings dataclass (its ``__post_init__`` checks every field).

    ``FIXED``: names of the fields that cannot change while the plugin runs (they size what it makes
    once); :func:`configure_settings` refuses them.
    """

    FIXED: ClassVar[tuple[str, ...]] = ()

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
