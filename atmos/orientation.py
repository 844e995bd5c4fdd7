"""Orientation from yaw, pitch and roll (radians): the one place the camera and transforms get their axes.

World y is up. Yaw 0 looks along −z and turns toward +x as it grows; pitch > 0 looks up; roll > 0
banks right (the right side goes down, as an aircraft rolling right), turning right and up about
the forward axis. ``basis`` is exact at pitch ±π/2 (the level right axis comes from yaw alone).
"""
from __future__ import annotations

import math

import numpy as np


def basis(yaw: float, pitch: float, roll: float = 0.0) -> np.ndarray:
    """3×3 float64 matrix with columns right, up, forward (orthonormal, right-handed: right × up = −forward)."""
    cy, sy, cp, sp = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    f0, f1, f2 = sy * cp, sp, -cy * cp                    # forward
    # level_up = cross(level_right, forward) with level_right = (cy, 0, sy), in scalars (np.cross
    # costs more than the whole basis; the same operations, so the same bits)
    u0, u1, u2 = 0.0 * f2 - sy * f1, sy * f0 - cy * f2, cy * f1 - 0.0 * f0
    cr, sr = math.cos(roll), math.sin(roll)
    return np.array([[cr * cy - sr * u0, cr * u0 + sr * cy, f0],
                     [cr * 0.0 - sr * u1, cr * u1 + sr * 0.0, f1],
                     [cr * sy - sr * u2, cr * u2 + sr * sy, f2]])


def angles(forward, up=None) -> tuple[float, float, float]:
    """(yaw, pitch, roll) of the orientation looking along ``forward`` with ``up`` as near the screen's
    up as it can be (``up`` need not be perpendicular to ``forward``; None: roll 0). The inverse of
    :func:`basis`; a ValueError for a zero ``forward`` or an ``up`` along it."""
    f = np.asarray(forward, np.float64)
    n = float(np.linalg.norm(f))
    if not (np.isfinite(f).all() and f.shape == (3,) and n > 0):
        raise ValueError(f"forward must be a finite, non-zero 3-vector, got {forward!r}")
    f = f / n
    yaw = math.atan2(f[0], -f[2]) if math.hypot(f[0], f[2]) > 1e-12 else 0.0
    pitch = math.asin(max(-1.0, min(1.0, f[1])))
    if up is None:
        return yaw, pitch, 0.0
    u = np.asarray(up, np.float64)
    u = u - np.dot(u, f) * f
    if not (np.isfinite(u).all() and np.linalg.norm(u) > 1e-9 * max(1.0, float(np.linalg.norm(up)))):
        raise ValueError(f"up must be a finite 3-vector not along forward, got {up!r}")
    level = basis(yaw, pitch, 0.0)
    roll = math.atan2(float(np.dot(u, level[:, 0])), float(np.dot(u, level[:, 1])))
    return yaw, pitch, roll
