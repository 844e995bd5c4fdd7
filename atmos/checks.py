"""Parameter checks whose ValueErrors name the setting, what was given and what is allowed.

Shared by parameter classes of the plugins (volumetric fog, sky layer, ...).
"""
from __future__ import annotations

import dataclasses
import math
import numbers
import operator

import numpy as np


def check_vec(owner: str, name: str, value, n: int, kind: str = "finite") -> tuple:
    """``n`` finite floats; ``kind`` 'positive' or 'non-negative' narrows them."""
    try:
        v = tuple(float(x) for x in value)
    except (TypeError, ValueError):
        v = ()
    ok = len(v) == n and all(math.isfinite(x) for x in v)
    if ok and kind == "positive":
        ok = min(v) > 0
    elif ok and kind == "non-negative":
        ok = min(v) >= 0
    if not ok:
        raise ValueError(f"{owner}.{name} must be {n} {kind} numbers, got {value!r}")
    return v


def check_num(owner: str, name: str, value, lo: float | None = None, hi: float | None = None,
              lo_open: bool = False) -> float:
    """A finite float within [lo, hi] (``lo_open``: strictly above lo)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    ok = math.isfinite(v) and (lo is None or (v > lo if lo_open else v >= lo)) and (hi is None or v <= hi)
    if not ok:
        bounds = [t for t in ("" if lo is None else f"{'>' if lo_open else '>='} {lo}",
                              "" if hi is None else f"<= {hi}") if t]
        raise ValueError(f"{owner}.{name} must be a finite number{' ' + ' and '.join(bounds) if bounds else ''}, "
                         f"got {value!r}")
    return v


def check_int(owner: str, name: str, value, lo: int, hi: int) -> int:
    """A whole number in lo..hi (bools are refused)."""
    try:
        v = None if isinstance(value, bool) else operator.index(value)
    except TypeError:
        v = None
    if v is None or not lo <= v <= hi:
        raise ValueError(f"{owner}.{name} must be a whole number {lo}..{hi}, got {value!r}")
    return v


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


def check_known(owner: str, changes: dict, known) -> None:
    """Refuse names that are not settings of ``owner``."""
    unknown = sorted(set(changes) - set(known))
    if unknown:
        raise ValueError(f"unknown {owner} setting(s) {', '.join(unknown)}; known: {', '.join(sorted(known))}")


class CheckedParams:
    """Base of the plugins' frozen settings dataclasses (their ``__post_init__`` checks every field)."""

    def replace(self, **changes):
        """A checked copy with ``changes``; unknown names and bad values raise ValueError."""
        check_known(type(self).__name__, changes, [f.name for f in dataclasses.fields(self)])
        return dataclasses.replace(self, **changes)


def plugin_params(plugin: str, cls, params, settings: dict):
    """A plugin's settings: ``params`` (a ``cls``, or None for the defaults) with keyword ``settings``
    applied on top, all checked before anything is kept."""
    if params is not None and not isinstance(params, cls):
        raise ValueError(f"{plugin} params must be a {cls.__name__}, got {type(params).__name__}")
    base = params if params is not None else cls()
    return base.replace(**settings) if settings else base
