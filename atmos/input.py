"""Input: keys, mouse and wheel as one resource, filled by the window or by a script (headless).

Keys and buttons are pyglet's constants (``atmos.key.W``, ``atmos.mouse.LEFT``; the same ints as
``pyglet.window.key``). What changed this frame (``pressed``, ``released``, motion, wheel) lasts
until the ``last`` stage of the frame, so every system of the frame sees it::

    inp = app.resource(Input)
    inp.press(key.SPACE); app.update(); inp.release(key.SPACE)     # a scripted tap
    if key.SPACE in inp.pressed: ...                                # in a system
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from atmos.checks import is_int
from atmos.plugin import Plugin


def _code(what: str, value) -> int:
    if not is_int(value):
        raise ValueError(f"Input.{what} takes a pyglet constant (atmos.key.W, atmos.mouse.LEFT), got {value!r}")
    return int(value)


def _finite(what: str, *values) -> tuple[float, ...]:
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        out = (math.nan,)
    if not all(math.isfinite(v) for v in out):
        raise ValueError(f"Input.{what} takes finite numbers, got {values!r}")
    return out


@dataclass
class Input:
    """``keys``: held now; ``pressed`` / ``released``: went down / up this frame. ``mouse``: the
    pointer in window pixels (origin bottom left, as pyglet), ``mouse_dx``/``mouse_dy`` its motion
    this frame; ``buttons`` held, ``buttons_pressed`` / ``buttons_released`` this frame;
    ``wheel``: (x, y) scroll this frame. Change it only through the methods."""
    keys: set = field(default_factory=set)
    pressed: set = field(default_factory=set)
    released: set = field(default_factory=set)
    mouse: tuple = (0.0, 0.0)
    mouse_dx: float = 0.0
    mouse_dy: float = 0.0
    buttons: set = field(default_factory=set)
    buttons_pressed: set = field(default_factory=set)
    buttons_released: set = field(default_factory=set)
    wheel: tuple = (0.0, 0.0)

    def press(self, key) -> None:
        """Key ``key`` went down (a key already held is not pressed again: no auto-repeat)."""
        k = _code("press", key)
        if k not in self.keys:
            self.keys.add(k)
            self.pressed.add(k)

    def release(self, key) -> None:
        k = _code("release", key)
        if k in self.keys:
            self.keys.discard(k)
            self.released.add(k)

    def move_mouse(self, x, y, dx=None, dy=None) -> None:
        """The pointer moved to (x, y) by (dx, dy) (default: from where it was); the motion adds to
        ``mouse_dx``/``mouse_dy``."""
        x, y = _finite("move_mouse", x, y)
        dx, dy = _finite("move_mouse", x - self.mouse[0] if dx is None else dx, y - self.mouse[1] if dy is None else dy)
        self.mouse_dx += dx
        self.mouse_dy += dy
        self.mouse = (x, y)

    def press_button(self, button) -> None:
        b = _code("press_button", button)
        if b not in self.buttons:
            self.buttons.add(b)
            self.buttons_pressed.add(b)

    def release_button(self, button) -> None:
        b = _code("release_button", button)
        if b in self.buttons:
            self.buttons.discard(b)
            self.buttons_released.add(b)

    def scroll(self, dy, dx=0.0) -> None:
        """The wheel turned by ``dy`` notches (``dx``: sideways)."""
        dy, dx = _finite("scroll", dy, dx)
        self.wheel = (self.wheel[0] + dx, self.wheel[1] + dy)

    def axis(self, negative, positive) -> float:
        """-1, 0 or 1 from two held keys (``axis(key.A, key.D)``)."""
        return float((positive in self.keys) - (negative in self.keys))

    def end_frame(self) -> None:
        """Forget this frame's changes (the ``last`` stage does it); what is held stays."""
        self.pressed.clear()
        self.released.clear()
        self.buttons_pressed.clear()
        self.buttons_released.clear()
        self.mouse_dx = self.mouse_dy = 0.0
        self.wheel = (0.0, 0.0)

    def clear(self) -> None:
        """Let go of everything (a window that lost focus never sees the releases)."""
        for k in list(self.keys):
            self.release(k)
        for b in list(self.buttons):
            self.release_button(b)


def end_input_frame(app) -> None:
    app.resource(Input).end_frame()


class InputPlugin(Plugin):
    """Adds the :class:`Input` resource and forgets each frame's changes in the ``last`` stage."""

    def build(self, app) -> None:
        app.insert_resource(Input())
        app.add_system(end_input_frame, "last", label="input_end_frame")
