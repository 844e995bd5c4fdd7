"""GLSL sources from the ``atmos.shaders`` package, with ``#include`` and errors that name file and line.

Every file included into a stage gets its own GLSL source-string number through ``#line``, so a
compiler message such as ``2:14(7): error: ...`` (Mesa) or ``2(14) : error ...`` (NVIDIA) is mapped
back to ``shaders/<file>:14``.
"""
from __future__ import annotations

import re
from functools import lru_cache
from importlib import resources

import moderngl

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')
_VERSION = re.compile(r"^\s*#version\b")
_MESSAGE = re.compile(r"^(\d+):(\d+)\((\d+)\):\s*(.*)$|^(\d+)\((\d+)\)\s*:\s*(.*)$")


class ShaderError(RuntimeError):
    """A GLSL file failed to load, compile or link; the message names the file and line."""


@lru_cache(maxsize=None)
def _read(name: str) -> str:
    path = resources.files("atmos.shaders").joinpath(*name.split("/"))
    if not path.is_file():
        raise ShaderError(f"shader file not found: shaders/{name}")
    return path.read_text(encoding="utf-8")


def load_source(name: str, defines: dict | None = None) -> tuple[str, list[str]]:
    """Return (GLSL text, files) for ``shaders/<name>``: includes expanded, ``defines`` added.

    ``files[i]`` is the file behind GLSL source-string number ``i`` used in ``#line`` directives.
    """
    files: list[str] = []
    lines: list[str] = []

    def expand(file: str, stack: tuple[str, ...]) -> None:
        if file in stack:
            raise ShaderError(f"shaders/{file}: #include cycle: {' -> '.join(stack + (file,))}")
        index = len(files)
        files.append(file)
        text = _read(file).splitlines()
        if stack:
            lines.append(f"#line 1 {index}")
        for number, line in enumerate(text, start=1):
            if _VERSION.match(line):
                if stack:
                    raise ShaderError(f"shaders/{file}:{number}: an included file must not have #version")
                lines.append(line)
                for key, value in (defines or {}).items():
                    lines.append(f"#define {key} {value}")
                lines.append(f"#line {number + 1} {index}")
                continue
            match = _INCLUDE.match(line)
            if match:
                expand(match.group(1), stack + (file,))
                lines.append(f"#line {number + 1} {index}")
            else:
                lines.append(line)

    expand(name, ())
    if not lines or not _VERSION.match(lines[0]):
        raise ShaderError(f"shaders/{name}:1: the first line must be a #version directive")
    return "\n".join(lines) + "\n", files


def explain(error: Exception, stages: dict[str, tuple[str, list[str]]]) -> ShaderError:
    """Turn a moderngl compile/link error into a ShaderError naming ``shaders/<file>:<line>``."""
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
        file = files[index] if index < len(files) else f"<source {index}>"
        messages.append(f"shaders/{file}:{line}: {message}")
    if not messages:
        names = ", ".join(f"shaders/{s[0]}" for s in stages.values())
        messages = [f"{names}: " + " ".join(l.strip() for l in text.splitlines() if l.strip())]
    return ShaderError(f"GLSL {kind} failed:\n" + "\n".join(messages))


def build_program(ctx: moderngl.Context, stages: dict[str, str], defines: dict | None = None):
    """Compile a program from shader file names keyed by moderngl stage name.

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
