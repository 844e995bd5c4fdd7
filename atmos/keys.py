"""pyglet's key and mouse-button constants, importable without a display: ``from atmos import key, mouse``.

``atmos.key.W is pyglet.window.key.W`` in value (the same ints), so a game uses either; headless
scripts (tests, ``atmos run --headless``) use these, since importing ``pyglet.window`` without a display
fails. ``key.symbol_string(key.W)`` names a key.
"""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path


def _pyglet_module(name: str):
    """``pyglet.window.<name>`` if pyglet.window is already imported, else that file run on its own
    (it imports nothing of pyglet's window system)."""
    loaded = sys.modules.get(f"pyglet.window.{name}")
    if loaded is not None:
        return loaded
    import pyglet
    path = Path(pyglet.__file__).parent / "window" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"atmos.keys._{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


key = _pyglet_module("key")
mouse = _pyglet_module("mouse")
