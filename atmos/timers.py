"""Timers in game time: ``app.after(seconds, fn)`` calls ``fn(app)`` once, ``app.every(seconds, fn,
times=None)`` repeatedly; both return a :class:`Timer` (``timer.cancel()``).

Game time is the App clock's frame time, ``app.clock.frame_time``: the sum of the frames' deltas, each
clamped to ``max_frame_dt``, so a hitch stretches timers as it stretches the simulation, and frames of
no time (or no frames) pause them. A timer is measured from the frame time when it is made. Timers do
not count fixed steps: the simulation's ``clock.time`` trails the frame time by less than a step.

When: due timers fire at the start of the ``update`` stage (the App's first update system, labelled
``"app.timers"``: before the game's update systems and so before that frame's fixed ``simulate``
steps), in the order of their due times, ties in the order they were made. A repeating timer keeps
its period (it fires at ``start + k * seconds``, no drift); one that falls several periods behind in
a long frame fires once per missed period, in order, within that frame (``timer.due`` in the call
says which period; a frame covers at most ``max_frame_dt`` of game time, so that is at most about
``max_frame_dt / seconds`` calls). A timer made in a timer's call fires no earlier than the next
frame; one cancelled in a call (its own or another's) fires no more, from then on. A call that raises
leaves ``update`` with the error; that call counts, and what else was due fires next frame.
"""
from __future__ import annotations

import heapq
from typing import Callable

from atmos.checks import check_num, is_int


class Timer:
    """``fn(app)`` every ``seconds`` of game time, ``times`` times (None: until cancelled); made by
    :meth:`atmos.App.after` (``times`` 1) and :meth:`atmos.App.every`.

    ``start``: the frame time it was made at; ``fired``: the calls made so far; ``due``: the game time
    of the next call (in a call: of this one, ``start + fired * seconds``); ``state``: the game state
    it belongs to (cancelled when the App leaves it) or None.
    """

    def __init__(self, seconds: float, fn: Callable, times: int | None, start: float, order: int,
                 state: str | None = None):
        self.seconds, self.fn, self.times, self.state = seconds, fn, times, state
        self.fired = 0
        self.start = start
        self.due = start + seconds
        self.cancelled = False
        self._order = order

    def cancel(self) -> None:
        """Call ``fn`` no more (works inside any timer's call, its own too); again: nothing."""
        self.cancelled = True

    @property
    def active(self) -> bool:
        """True while it will fire again: not cancelled and fewer than ``times`` calls made."""
        return not self.cancelled and (self.times is None or self.fired < self.times)

    @property
    def remaining(self) -> int | None:
        """Calls still to come (None: until cancelled; 0 once cancelled or done)."""
        if not self.active:
            return 0
        return None if self.times is None else self.times - self.fired

    def __repr__(self) -> str:
        name = getattr(self.fn, "__qualname__", None) or type(self.fn).__name__
        every = "once" if self.times == 1 else f"every {self.seconds:g} s" + (
            f" x{self.times}" if self.times else "")
        status = "active" if self.active else ("cancelled" if self.cancelled else "done")
        return f"<Timer {name} {every}, fired {self.fired}, {status}>"


class Timers:
    """The App's timers (``app.timers``): :meth:`add` makes one, :meth:`run` fires the due ones."""

    def __init__(self):
        self.timers: list[Timer] = []
        self._made = 0

    def add(self, owner: str, seconds, fn, times, now: float, state: str | None = None) -> Timer:
        """A checked timer (ValueErrors name ``owner.argument`` and what is allowed), started at ``now``."""
        seconds = check_num(owner, "seconds", seconds, 0.0, lo_open=True)
        if not callable(fn):
            raise ValueError(f"{owner}.fn must be a callable fn(app), got {fn!r}")
        if times is not None and not (is_int(times) and times >= 1):
            raise ValueError(f"{owner}.times must be a whole number >= 1, or None to repeat until "
                             f"cancelled, got {times!r}")
        self._made += 1
        timer = Timer(seconds, fn, None if times is None else int(times), now, self._made, state)
        self.timers.append(timer)
        return timer

    def run(self, app) -> None:
        """Fire every timer due at ``app.clock.frame_time`` (module docstring: order, catch-up)."""
        now = app.clock.frame_time
        now += 1e-9 * max(1.0, abs(now))             # the frame time is a float sum
        due = [(t.due, t._order, t) for t in self.timers if t.active and t.due <= now]
        heapq.heapify(due)
        try:
            while due:
                _, _, timer = heapq.heappop(due)
                if not timer.active:                  # cancelled by an earlier call this frame
                    continue
                timer.fired += 1
                try:
                    timer.fn(app)
                finally:
                    timer.due = timer.start + (timer.fired + 1) * timer.seconds
                if timer.active and timer.due <= now:
                    heapq.heappush(due, (timer.due, timer._order, timer))
        finally:
            self.timers = [t for t in self.timers if t.active]

    def cancel_state(self, state: str) -> None:
        """Cancel the timers that belong to ``state`` (the App is leaving it)."""
        for timer in self.timers:
            if timer.state == state:
                timer.cancel()

    @property
    def active(self) -> list[Timer]:
        """The timers that will fire again, in the order they were made."""
        return [t for t in self.timers if t.active]

    def mark(self) -> list[Timer]:
        """What :meth:`undo` needs to cancel the timers made after now (a failed plugin build)."""
        return list(self.timers)

    def undo(self, mark: list[Timer]) -> None:
        kept = {id(t) for t in mark}
        for timer in self.timers:
            if id(timer) not in kept:
                timer.cancel()
        self.timers = [t for t in self.timers if id(t) in kept]
