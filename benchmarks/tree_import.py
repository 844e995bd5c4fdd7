"""Import atmos from a source tree without installing it: ``python benchmarks/tree_import.py TREE
SCRIPT [ARGS...]`` runs SCRIPT with ``atmos`` (and ``atmos.plugins``, ``atmos.demos``,
``atmos.shaders``, which the wheel maps from ``plugins/``, ``demos/``, ``shaders/``) found in TREE.
What bench_python_frame.py's ``--baseline`` measures an older tree with.

``python benchmarks/tree_import.py --site SITE TREE`` makes a folder that, on ``PYTHONPATH`` with
``ATMOS_TREE=TREE`` exported, gives every Python process (pytest-xdist workers, ``python -m atmos``)
atmos from TREE as if installed: a ``sitecustomize.py`` that installs the finder, an atmos
dist-info with the project's entry points, and ``bin/atmos``. What a GPU machine with no package
index uses (benchmarks/nvidia/env.sh).
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


SITECUSTOMIZE = """\
# Written by atmos's benchmarks/tree_import.py --site: atmos is imported from $ATMOS_TREE.
import importlib.util as _util
import os as _os

if _os.environ.get("ATMOS_TREE"):
    _spec = _util.spec_from_file_location(
        "_atmos_tree_import", _os.path.join(_os.environ["ATMOS_TREE"], "benchmarks", "tree_import.py"))
    _module = _util.module_from_spec(_spec)
    _spec.loader.exec_module(_module)
    _module.install(_os.environ["ATMOS_TREE"])
"""


def write_site(site, tree) -> None:
    """Write ``sitecustomize.py``, an atmos dist-info (name, version, entry points from TREE's
    pyproject.toml) and ``bin/atmos`` into the folder ``site``."""
    import tomllib
    site, tree = Path(site), Path(tree).resolve()
    project = tomllib.loads((tree / "pyproject.toml").read_text())["project"]
    dist = site / f"atmos-{project['version']}.dist-info"
    dist.mkdir(parents=True, exist_ok=True)
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: atmos\nVersion: {project['version']}\n")
    groups = {"console_scripts": project.get("scripts", {}), **project.get("entry-points", {})}
    (dist / "entry_points.txt").write_text("".join(
        f"[{group}]\n" + "".join(f"{name} = {target}\n" for name, target in points.items()) + "\n"
        for group, points in groups.items()))
    (site / "sitecustomize.py").write_text(SITECUSTOMIZE)
    (site / "bin").mkdir(exist_ok=True)
    script = site / "bin" / "atmos"
    script.write_text("#!/usr/bin/env python3\nimport sys\nfrom atmos.cli import main\nsys.exit(main())\n")
    script.chmod(0o755)


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--site":
        write_site(sys.argv[2], sys.argv[3])
        raise SystemExit(0)
    if len(sys.argv) < 3:
        raise SystemExit(__doc__.splitlines()[1].strip())
    install(sys.argv[1])
    script = sys.argv[2]
    sys.argv = sys.argv[2:]
    sys.path.insert(0, str(Path(script).resolve().parent))
    runpy.run_path(script, run_name="__main__")
