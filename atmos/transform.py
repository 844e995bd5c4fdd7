"""Transform: where an entity is (position, yaw/pitch/roll, scale), and its pose one fixed step ago, so
drawing can interpolate between fixed steps by ``clock.alpha`` and simulated motion does not stutter.

Move entities in ``simulate`` systems (fixed step); draw ``transform.interpolated(app.clock.alpha)``.
An entity with a :class:`Parent` is placed in its parent's frame (:func:`world_matrix`).
The TransformPlugin keeps ``previous`` by running its snapshot first in every fixed step (its
``finish`` orders it before every other ``simulate`` system). A teleport (a reset) calls
:meth:`Transform.teleport`, so it is not smeared over a step.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from atmos.checks import check_num, check_vec
from atmos.orientation import basis
from atmos.plugin import Plugin


@dataclass(frozen=True, slots=True)
class Pose:
    """A position and yaw/pitch/roll (radians, :mod:`atmos.orientation`)."""
    position: tuple
    yaw: float = 0.0
    pitch: float = 0.0
    roll: float = 0.0

    def basis(self) -> np.ndarray:
        return basis(self.yaw, self.pitch, self.roll)

    def matrix(self, scale=1.0) -> np.ndarray:
        """4×4 model matrix: scale, then rotate (columns right, up, −forward: a model's −z is its front),
        then translate."""
        m = np.identity(4)
        r = self.basis() * [1.0, 1.0, -1.0]
        m[:3, :3] = r * np.broadcast_to(np.asarray(scale, np.float64), 3)
        m[:3, 3] = self.position
        return m


def _turn(a: float, b: float, t: float) -> float:
    """From angle a toward b by fraction t, the short way round."""
    d = math.remainder(b - a, 2.0 * math.pi)
    return a + d * t


@dataclass(slots=True)
class Transform:
    """An entity's pose now (``position``, ``yaw``, ``pitch``, ``roll``), its ``scale`` (a number or
    three) and ``previous``, the pose at the start of the last fixed step. A model's front is its −z."""
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    yaw: float = 0.0
    pitch: float = 0.0
    roll: float = 0.0
    scale: float | tuple = 1.0
    previous: Pose | None = None

    def __post_init__(self):
        self.position = np.array(check_vec("Transform", "position", self.position, 3), np.float64)
        for name in ("yaw", "pitch", "roll"):
            setattr(self, name, check_num("Transform", name, getattr(self, name)))
        scale = (self.scale,) * 3 if np.ndim(self.scale) == 0 else self.scale
        check_vec("Transform", "scale", scale, 3, "positive")
        if self.previous is None:
            self.previous = self.pose()

    def pose(self) -> Pose:
        return Pose(tuple(float(v) for v in self.position), float(self.yaw), float(self.pitch), float(self.roll))

    def basis(self) -> np.ndarray:
        """Columns right, up, forward of the pose now."""
        return basis(self.yaw, self.pitch, self.roll)

    def forward(self) -> np.ndarray:
        return self.basis()[:, 2]

    def teleport(self, position, yaw=None, pitch=None, roll=None) -> None:
        """Jump (no interpolation from where it was)."""
        self.position = np.array(check_vec("Transform", "position", position, 3), np.float64)
        for name, value in (("yaw", yaw), ("pitch", pitch), ("roll", roll)):
            if value is not None:
                setattr(self, name, check_num("Transform", name, value))
        self.previous = self.pose()

    def interpolated(self, alpha: float) -> Pose:
        """The pose ``alpha`` (``app.clock.alpha``, 0..1) of the way from ``previous`` to now: what to
        draw between fixed steps. Angles turn the short way."""
        a = min(max(float(alpha), 0.0), 1.0) if math.isfinite(alpha) else 1.0
        p = self.previous
        position = tuple(float(v) for v in np.asarray(p.position) + a * (self.position - np.asarray(p.position)))
        return Pose(position, _turn(p.yaw, self.yaw, a), p.pitch + a * (self.pitch - p.pitch),
                    _turn(p.roll, self.roll, a))


@dataclass(frozen=True, slots=True)
class Parent:
    """This entity's Transform is relative to entity ``entity``'s (a basket under its balloon): its
    position, turns and scale are in the parent's frame, and it moves with the parent."""
    entity: int

    def __post_init__(self):
        if isinstance(self.entity, bool) or not isinstance(self.entity, (int, np.integer)) or self.entity < 0:
            raise ValueError(f"Parent.entity must be an entity id (an int >= 0), got {self.entity!r}")


MAX_DEPTH = 64          # parents above one entity: deeper is a cycle or a mistake


def world_matrix(world, entity: int, alpha: float = 1.0) -> np.ndarray:
    """The 4×4 model matrix of ``entity`` in the world: its Transform ``alpha`` of the way from its last
    fixed step, under each :class:`Parent`'s in turn. A parent without a Transform, a missing parent
    or a cycle is a ValueError naming the entity."""
    m, seen = np.identity(4), [entity]
    while True:
        transform = world.try_component(entity, Transform)
        if transform is None:
            raise ValueError(f"entity {seen[0]}: {'its parent ' if len(seen) > 1 else ''}entity {entity} has no "
                             f"Transform, so it cannot be placed")
        m = transform.interpolated(alpha).matrix(transform.scale) @ m
        parent = world.try_component(entity, Parent)
        if parent is None:
            return m
        entity = int(parent.entity)
        if entity in seen or len(seen) > MAX_DEPTH:
            raise ValueError(f"entity {seen[0]}: its parents {seen + [entity]} form a cycle (or are deeper than "
                             f"{MAX_DEPTH})")
        if not world.has_entity(entity):
            raise ValueError(f"entity {seen[0]}: its parent entity {entity} does not exist (deleted?)")
        seen.append(entity)


def snapshot_transforms(app) -> None:
    """Remember every Transform's pose as ``previous`` (first in each fixed step)."""
    for _, transform in app.world.get_component(Transform):
        transform.previous = transform.pose()


class TransformPlugin(Plugin):
    """Keeps :attr:`Transform.previous` one fixed step behind, for :meth:`Transform.interpolated`."""

    def finish(self, app) -> None:
        others = [s.label for s in app.schedule.systems if s.stage == "simulate"]
        app.add_system(snapshot_transforms, "simulate", label="snapshot_transforms", before=others)
