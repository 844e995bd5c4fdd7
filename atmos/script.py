"""Scripted runs: a script's ``step(app, frame)`` runs at the start of every frame, before the game's
systems, so it can press keys and move the mouse through the :class:`atmos.Input` resource as a player
would (``atmos run game.py --script play.py``, ``atmos.run(..., script=...)``). ``frame`` counts from
0; the Input's per-frame state is cleared at the end of each frame as for a player's input."""
from __future__ import annotations

import importlib.util
import os
from pathlib import Path
from typing import Callable

from atmos.plugin import Plugin


def load_script(script) -> Callable:
    """``step(app, frame)`` of ``script``: the function itself, or the path of a ``.py`` file that
    defines it; ValueError otherwise."""
    if callable(script):
        return script
    if not isinstance(script, (str, os.PathLike)):
        raise ValueError(f"script must be a step(app, frame) function or the path of a .py file that defines "
                         f"one, got {script!r}")
    path = Path(script)
    if path.suffix != ".py" or not path.is_file():
        raise ValueError(f"script {path}: no such .py file (it must define step(app, frame))")
    spec = importlib.util.spec_from_file_location(f"atmos_script_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    step = getattr(module, "step", None)
    if not callable(step):
        raise ValueError(f"script {path} defines no step(app, frame) function")
    return step


class ScriptPlugin(Plugin):
    """Runs ``step(app, frame)`` (:func:`load_script`) first in the update stage of every frame; add it
    before the game's plugins so its system comes first."""

    def __init__(self, script):
        super().__init__()
        self.step = load_script(script)
        self.frame = 0

    def build(self, app) -> None:
        app.add_system(self._run, "update", label="script")

    def _run(self, app) -> None:
        self.step(app, self.frame)
        self.frame += 1
