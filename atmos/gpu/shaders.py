"""GLSL sources on a search path, with ``#include`` and errors that name file and line.

A shader is named by a ``/``-separated path such as ``"sky/sky.frag"`` or ``"lib/view_ray.glsl"``,
in :meth:`GpuContext.program <atmos.gpu.GpuContext.program>` and in ``#include "..."`` alike. Names
are looked up along the search path, first match wins:

1. atmos's own ``shaders/`` (the ``atmos.shaders`` package), so ``#include "lib/view_ray.glsl"``
   always means atmos's ``shaders/lib/`` and no plugin can replace or break atmos's files;
2. the directories registered with :func:`add_shader_path`, in the order they were added. A
   directory registered with ``prefix="mypkg"`` serves only the names ``"mypkg/..."`` (the rest of
   the name is its path inside the directory), so two plugins' ``glow.frag`` never collide.

A third-party plugin ships its GLSL beside its Python and registers it once, e.g. in ``build``::

    add_shader_path(Path(__file__).parent / "shaders", prefix="mypkg")
    gpu.program(vertex_shader="lib/fullscreen.vert", fragment_shader="mypkg/glow.frag")

Every file included into a stage gets its own GLSL source-string number through ``#line``, so a
compiler message such as ``2:14(7): error: ...`` (Mesa) or ``2(14) : error ...`` (NVIDIA) is mapped
back to the real file: ``shaders/<name>:14`` for atmos's files, ``<directory>/<path>:14`` (the
directory as it was registered) for the others. A name found nowhere is an error that lists every
place it was looked for.
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

import moderngl

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')
_VERSION = re.compile(r"^\s*#version\b")
_MESSAGE = re.compile(r"^(\d+):(\d+)\((\d+)\):\s*(.*)$|^(\d+)\((\d+)\)\s*:\s*(.*)$")


class ShaderError(RuntimeError):
    """A GLSL file failed to load, compile or link; the message names the file and line."""


@dataclass(frozen=True)
class _Dir:
    """A registered shader directory: ``shown`` is how errors name it (as it was given)."""
    path: Path
    prefix: str | None
    shown: str


_PATHS: list[_Dir] = []


def _check_prefix(prefix) -> str | None:
    if prefix is None:
        return None
    parts = prefix.split("/") if isinstance(prefix, str) else None
    if not parts or any(p in ("", ".", "..") for p in parts):
        raise ValueError(f"prefix must be None or a name like 'mypkg' or 'mypkg/fx' (no leading or trailing "
                         f"'/', no '.' or '..' parts), got {prefix!r}")
    return prefix


def add_shader_path(directory, prefix: str | None = None) -> None:
    """Add ``directory`` to the end of the shader search path (see the module docstring).

    With ``prefix="mypkg"`` the directory serves the names ``"mypkg/<path>"`` as ``directory/<path>``;
    with ``prefix=None`` it serves every name directly. Adding the same (directory, prefix) again
    does nothing. Register before the programs are first compiled: :class:`~atmos.gpu.GpuContext`
    keeps a compiled program for the rest of its life.
    """
    path = Path(os.fspath(directory))
    if not path.is_dir():
        raise ValueError(f"shader directory not found: {os.fspath(directory)}")
    entry = _Dir(path.resolve(), _check_prefix(prefix), os.fspath(directory).rstrip("/\\") or "/")
    if any(d.path == entry.path and d.prefix == entry.prefix for d in _PATHS):
        return
    _PATHS.append(entry)
    _locate.cache_clear()


def remove_shader_path(directory, prefix: str | None = None) -> None:
    """Take a directory added by :func:`add_shader_path` (same ``prefix``) off the search path again."""
    path = Path(os.fspath(directory)).resolve()
    _PATHS[:] = [d for d in _PATHS if not (d.path == path and d.prefix == prefix)]
    _locate.cache_clear()


def shader_paths() -> list[str]:
    """The search path in order, as errors name it: ``"shaders/ (atmos.shaders)"`` first."""
    return ["shaders/ (atmos.shaders)"] + [f"{d.shown}/" + (f" (prefix {d.prefix}/)" if d.prefix else "")
                                           for d in _PATHS]


@lru_cache(maxsize=None)
def _locate(name: str) -> tuple[str, str]:
    """(how errors name the file, its text) for shader ``name``: the first match on the search path."""
    parts = name.split("/")
    if not name or any(p in ("", ".", "..") for p in parts) or "\\" in name:
        raise ShaderError(f"shader names are relative '/'-separated paths like 'lib/view_ray.glsl'; got {name!r}")
    tried = [f"shaders/{name}"]
    builtin = resources.files("atmos.shaders").joinpath(*parts)
    if builtin.is_file():
        return f"shaders/{name}", builtin.read_text(encoding="utf-8")
    for d in _PATHS:
        rest = parts
        if d.prefix is not None:
            head = d.prefix.split("/")
            if parts[:len(head)] != head or len(parts) == len(head):
                continue
            rest = parts[len(head):]
        shown = "/".join([d.shown, *rest])
        tried.append(shown)
        file = d.path.joinpath(*rest)
        if file.is_file():
            return shown, file.read_text(encoding="utf-8")
    raise ShaderError(f"shader file not found: {name} (looked for {', '.join(tried)}; "
                      f"search path: {'; '.join(shader_paths())}; add a directory with atmos.gpu.add_shader_path)")


def _display(name: str) -> str:
    """How errors name shader ``name`` (its real file when found)."""
    try:
        return _locate(name)[0]
    except ShaderError:
        return name


def load_source(name: str, defines: dict | None = None) -> tuple[str, list[str]]:
    """Return (GLSL text, files) for shader ``name``: includes expanded, ``defines`` added.

    ``files[i]`` is the name of the file behind GLSL source-string number ``i`` used in ``#line``
    directives (where each lives: :func:`shader_paths`).
    """
    files: list[str] = []
    lines: list[str] = []

    def expand(file: str, stack: tuple[str, ...]) -> None:
        if file in stack:
            raise ShaderError(f"{_display(file)}: #include cycle: {' -> '.join(stack + (file,))}")
        index = len(files)
        shown, source = _locate(file)
        files.append(file)
        text = source.splitlines()
        if stack:
            lines.append(f"#line 1 {index}")
        for number, line in enumerate(text, start=1):
            if _VERSION.match(line):
                if stack:
                    raise ShaderError(f"{shown}:{number}: an included file must not have #version")
                lines.append(line)
                for key, value in (defines or {}).items():
                    lines.append(f"#define {key} {value}")
                lines.append(f"#line {number + 1} {index}")
                continue
            match = _INCLUDE.match(line)
            if match:
                try:
                    expand(match.group(1), stack + (file,))
                except ShaderError as error:
                    if "shader file not found" not in str(error) or " (included from " in str(error):
                        raise
                    raise ShaderError(f"{error} (included from {shown}:{number})") from None
                lines.append(f"#line {number + 1} {index}")
            else:
                lines.append(line)

    expand(name, ())
    if not lines or not _VERSION.match(lines[0]):
        raise ShaderError(f"{_display(name)}:1: the first line must be a #version directive")
    return "\n".join(lines) + "\n", files


def explain(error: Exception, stages: dict[str, tuple[str, list[str]]]) -> ShaderError:
    """Turn a moderngl compile/link error into a ShaderError naming ``<file>:<line>`` (the real file)."""
    text = str(error)
    kind = "link" if "Linker" in text else "compile"
    stage = next((s for s in stages if s in text), None)
    files = stages[stage][1] if stage else []
    messages = []
    for raw in text.splitlines():
        match = _MESSAGE.match(raw.strip())
        if not match:
            continue
        if match.group(1) is not None:
            index, line, message = int(match.group(1)), match.group(2), match.group(4)
        else:
            index, line, message = int(match.group(5)), match.group(6), match.group(7)
        file = _display(files[index]) if index < len(files) else f"<source {index}>"
        messages.append(f"{file}:{line}: {message}")
    if not messages:
        names = ", ".join(_display(s[0]) for s in stages.values())
        messages = [f"{names}: " + " ".join(l.strip() for l in text.splitlines() if l.strip())]
    return ShaderError(f"GLSL {kind} failed:\n" + "\n".join(messages))


def build_program(ctx: moderngl.Context, stages: dict[str, str], defines: dict | None = None):
    """Compile a program from shader file names keyed by moderngl stage name: the internal of
    :meth:`GpuContext.program <atmos.gpu.GpuContext.program>`, which caches and releases what
    this makes (everything else asks the GpuContext).

    ``stages`` holds ``vertex_shader``/``fragment_shader``/``geometry_shader`` names for a render
    program, or ``compute_shader`` alone for a compute program.
    """
    sources = {stage: load_source(name, defines) for stage, name in stages.items()}
    try:
        if "compute_shader" in sources:
            return ctx.compute_shader(sources["compute_shader"][0])
        return ctx.program(**{stage: src for stage, (src, _) in sources.items()})
    except moderngl.Error as error:
        raise explain(error, {s: (stages[s], f) for s, (_, f) in sources.items()}) from None
