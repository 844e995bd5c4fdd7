"""Import atmos from a source tree without installing it: ``python benchmarks/tree_import.py TREE
SCRIPT [ARGS...]`` runs SCRIPT with ``atmos`` (and ``atmos.plugins``, ``atmos.demos``,
``atmos.shaders``, which the wheel maps from ``plugins/``, ``demos/``, ``shaders/``) found in TREE.

What a GPU machine with no package index uses (benchmarks/nvidia/run.sh), and what
bench_python_frame.py's ``--baseline`` measures an older tree with. Entry points are not registered
(nothing in the benchmarks needs them).
"""
from __future__ import annotations

import importlib.util
import runpy
import sys
from pathlib import Path

FOLDERS = {"atmos": "atmos", "atmos.plugins": "plugins", "atmos.demos": "demos", "atmos.shaders": "shaders"}


class TreeFinder:
    """A meta path finder for the four top folders of one atmos tree (submodules follow their paths)."""

    def __init__(self, tree):
        self.tree = Path(tree).resolve()

    def find_spec(self, name, path=None, target=None):
        folder = FOLDERS.get(name)
        if folder is None:
            return None
        where = self.tree / folder
        return importlib.util.spec_from_file_location(name, where / "__init__.py", submodule_search_locations=[str(where)])


def install(tree) -> TreeFinder:
    """Put a :class:`TreeFinder` for ``tree`` first on ``sys.meta_path`` (before any atmos import)."""
    if any(name in sys.modules for name in FOLDERS):
        raise RuntimeError("tree_import.install must run before atmos is imported")
    finder = TreeFinder(tree)
    sys.meta_path.insert(0, finder)
    return finder


if __name__ == "__main__":
    if len(sys.argv) < 3:
        raise SystemExit(__doc__.splitlines()[1].strip())
    install(sys.argv[1])
    script = sys.argv[2]
    sys.argv = sys.argv[2:]
    sys.path.insert(0, str(Path(script).resolve().parent))
    runpy.run_path(script, run_name="__main__")
