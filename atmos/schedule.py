"""Named stages in a fixed order, and systems ordered inside a stage by ``before``/``after`` labels."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from atmos.toposort import CycleError, stable_toposort

#: Stages in the order one frame runs them. ``startup`` runs once before the first frame;
#: ``simulate`` runs zero or more times a frame, once per fixed simulation step (see FixedClock);
#: ``last`` ends the frame (per-frame input is cleared there).
STAGES = ("startup", "update", "simulate", "render", "last")


class ScheduleError(ValueError):
    """A system's stage, label or ordering is invalid; the message names the systems involved."""


@dataclass
class System:
    """A function ``func(app)`` run in ``stage``; ``label`` names it for others' before/after."""
    func: Callable
    stage: str
    label: str
    before: tuple[str, ...] = ()
    after: tuple[str, ...] = ()
    index: int = field(default=0, compare=False)


class Schedule:
    """Systems per stage; :meth:`build` resolves the order once and reports every problem."""

    def __init__(self):
        self.systems: list[System] = []
        self._order: dict[str, list[System]] | None = None

    def add(self, func: Callable, stage: str = "update", label: str | None = None,
            before=(), after=()) -> System:
        if not callable(func):
            raise ScheduleError(f"a system must be a callable func(app), got {type(func).__name__} {func!r}")
        if stage not in STAGES:
            raise ScheduleError(f"unknown stage {stage!r} for system {_name(func)}; stages are {', '.join(STAGES)}")
        if label is not None and (not isinstance(label, str) or not label):
            raise ScheduleError(f"system {_name(func)}: label must be a non-empty string or None, got {label!r}")
        label = label or _name(func)
        if any(s.label == label for s in self.systems):
            raise ScheduleError(f"two systems are labelled {label!r}; labels must be unique (pass label=...)")
        system = System(func, stage, label, _labels(label, "before", before), _labels(label, "after", after),
                        len(self.systems))
        self.systems.append(system)
        self._order = None
        return system

    def truncate(self, count: int) -> None:
        """Forget every system added after the first ``count`` (undoing a failed plugin build)."""
        if count < len(self.systems):
            del self.systems[count:]
            self._order = None

    def build(self) -> dict[str, list[System]]:
        """Order each stage; unknown labels, cross-stage labels and cycles raise ScheduleError."""
        if self._order is not None:
            return self._order
        by_label = {s.label: s for s in self.systems}
        order = {}
        for stage in STAGES:
            systems = [s for s in self.systems if s.stage == stage]
            edges = []
            for s in systems:
                for other, pair in [(o, (s.label, o)) for o in s.before] + [(o, (o, s.label)) for o in s.after]:
                    target = by_label.get(other)
                    if target is None:
                        raise ScheduleError(f"system {s.label!r} is ordered relative to unknown label {other!r}; "
                                            f"known labels: {', '.join(sorted(by_label)) or 'none'}")
                    if target.stage != stage:
                        raise ScheduleError(f"system {s.label!r} (stage {stage}) is ordered relative to "
                                            f"{other!r} in stage {target.stage}; before/after work inside one stage")
                    edges.append(pair)
            try:
                labels = stable_toposort([s.label for s in systems], edges)
            except CycleError as cycle:
                raise ScheduleError(f"systems in stage {stage!r} form an ordering cycle: {cycle}") from None
            order[stage] = [by_label[label] for label in labels]
        self._order = order
        return order

    def run(self, stage: str, app) -> None:
        for system in self.build()[stage]:
            system.func(app)


def _labels(system: str, name: str, value) -> tuple[str, ...]:
    """``before``/``after``: one label or an iterable of labels (non-empty strings)."""
    try:
        labels = (value,) if isinstance(value, str) else tuple(value)
    except TypeError:
        labels = None
    if labels is None or not all(isinstance(v, str) and v for v in labels):
        raise ScheduleError(f"system {system!r}: {name} must be a label or a list of labels (non-empty "
                            f"strings), got {value!r}")
    return labels


def _name(func: Callable) -> str:
    return getattr(func, "__qualname__", None) or type(func).__name__
