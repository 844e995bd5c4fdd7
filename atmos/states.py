"""Game states (menu -> play -> game over), small and Bevy-like: one set of named states per App.

``app.add_state("menu", "play", "game_over", initial="menu")`` declares them; ``app.state`` is the
current one; ``app.add_system(fn, stage, in_state="play")`` runs ``fn`` only in that state;
``app.on_enter(state, fn)`` / ``app.on_exit(state, fn)`` register hooks ``fn(app)``;
``app.after(..., in_state="play")`` makes a timer that belongs to the state.

When: ``app.set_state(name)`` asks for a change; it takes effect at the next frame boundary: the end
of the current frame (after the ``last`` stage), or, asked for between frames, the start of the next
one (before its ``update`` stage). So one frame runs in one state throughout, and ``app.state`` is the
new state when ``update`` returns. A change runs the old state's on_exit hooks (``app.state`` still
the old one), cancels the timers that belong to it, switches, then runs the new state's on_enter
hooks (in the order registered). The initial state is entered (its on_enter hooks) after the
``startup`` stage. Asked for twice before the boundary, the last one wins; asking for the current
state restarts it (on_exit, then on_enter). A hook that asks for a state has it applied at once, at
the same boundary. Unknown names are a ValueError naming the known states.
"""
from __future__ import annotations

from typing import Callable

#: State changes at one frame boundary beyond which hooks that keep asking for states are an error.
MAX_CHAINED = 100


class InState:
    """A system ``func(app)`` that runs only while the App is in ``state`` (``add_system(in_state=)``)."""

    def __init__(self, func: Callable, state: str):
        self.func, self.state = func, state
        self.__qualname__ = getattr(func, "__qualname__", None) or type(func).__name__

    def __call__(self, app) -> None:
        if app.states.current == self.state:
            self.func(app)

    def __repr__(self) -> str:
        return f"<{self.__qualname__} in state {self.state!r}>"


class States:
    """The App's states (``app.states``): ``names``, ``current``, ``next`` (asked for, not yet
    applied), ``previous`` (the state before the last change), and the on_enter/on_exit hooks."""

    def __init__(self):
        self.names: tuple[str, ...] = ()
        self.current: str | None = None
        self.next: str | None = None
        self.previous: str | None = None
        self._entered = False
        self._hooks: dict[str, dict[str, list[Callable]]] = {"enter": {}, "exit": {}}

    def declare(self, owner: str, names, initial) -> None:
        """The states, once per App; ``initial`` (default: the first) is the current one."""
        if self.names:
            raise ValueError(f"{owner}: this App's states are already declared ({self._known()}); an App has "
                             f"one set of states, declared in one call")
        names = tuple(names)
        if not names or not all(isinstance(n, str) and n for n in names):
            raise ValueError(f"{owner}: states must be one or more names (non-empty strings), got "
                             f"{', '.join(map(repr, names)) or 'none'}")
        doubled = sorted({n for n in names if names.count(n) > 1})
        if doubled:
            raise ValueError(f"{owner}: state {', '.join(map(repr, doubled))} is named twice; names must be unique")
        if initial is None:
            initial = names[0]
        elif not isinstance(initial, str) or initial not in names:
            raise ValueError(f"{owner}.initial must be one of the states {', '.join(map(repr, names))}, "
                             f"got {initial!r}")
        self.names, self.current = names, initial

    def check(self, owner: str, name, argument: str = "state") -> str:
        """``name`` if it is one of the states; else a ValueError naming the known ones."""
        if not self.names:
            raise ValueError(f"{owner}: {argument}={name!r}, but this App has no states; declare them first "
                             f"with app.add_state('menu', 'play', ...)")
        if not isinstance(name, str) or name not in self.names:
            raise ValueError(f"{owner}.{argument} must be one of the states {self._known()}, got {name!r}")
        return name

    def hook(self, owner: str, kind: str, state, fn) -> None:
        """Register ``fn(app)`` to run on entering (``kind`` 'enter') or leaving ('exit') ``state``."""
        self.check(owner, state)
        if not callable(fn):
            raise ValueError(f"{owner}.fn must be a callable fn(app), got {fn!r}")
        self._hooks[kind].setdefault(state, []).append(fn)

    def apply(self, app) -> bool:
        """At a frame boundary: enter the initial state once, then make the changes asked for
        (module docstring). True when any change or entry happened."""
        if not self.names:
            return False
        changed = False
        if not self._entered:
            self._entered = changed = True
            self._run("enter", self.current, app)
        for _ in range(MAX_CHAINED):
            if self.next is None:
                return changed
            new, self.next = self.next, None
            self._run("exit", self.current, app)
            app.timers.cancel_state(self.current)
            self.previous, self.current = self.current, new
            self._run("enter", new, app)
            changed = True
        raise RuntimeError(f"the state changed {MAX_CHAINED} times at one frame boundary (last: "
                           f"{self.previous!r} -> {self.current!r}); on_enter/on_exit hooks keep asking for "
                           f"states, each other's in a loop")

    def _run(self, kind: str, state: str, app) -> None:
        for fn in list(self._hooks[kind].get(state, ())):
            fn(app)

    def _known(self) -> str:
        return ", ".join(map(repr, self.names))

    def mark(self) -> tuple:
        """What :meth:`undo` needs to take back states and hooks declared after now (a failed plugin build)."""
        return (self.names, self.current, self.next, self.previous, self._entered,
                {kind: {s: list(fns) for s, fns in hooks.items()} for kind, hooks in self._hooks.items()})

    def undo(self, mark: tuple) -> None:
        self.names, self.current, self.next, self.previous, self._entered, hooks = mark
        self._hooks = {kind: {s: list(fns) for s, fns in by_state.items()} for kind, by_state in hooks.items()}
