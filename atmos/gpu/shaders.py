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

A stage is assembled into one text without ``#line`` directives, and each of its lines remembers
the file and line it came from, so a compiler message such as ``0:14(7): error: ...`` (Mesa) or
``0(14) : error ...`` (NVIDIA) names the real file: ``shaders/<name>:14`` for atmos's files,
``<directory>/<path>:14`` (the directory as it was registered) for the others. A name found nowhere is an error that lists every
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

from atmos.gpu.hazards import hazards_of

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*(//.*)?$')   # a trailing // comment allowed
_VERSION = re.compile(r"^\s*#version\b")
_LAYOUT = r"^[ \t]*(?:layout\s*\((?P<layout>[^)]*)\)\s*)?"
_WORDS = r"(?:(?:coherent|volatile|restrict|readonly|writeonly|lowp|mediump|highp)\s+)*"
_UNIFORM = r"(?P<before>" + _WORDS + r")uniform\s+(?P<after>" + _WORDS + r")"
_BINDINGS = {   # what a program binds by name, and the unit namespace each kind has
    "sampler": re.compile(_LAYOUT + _UNIFORM + r"[iu]?sampler\w*\s+(?P<name>\w+)", re.M),
    "image": re.compile(_LAYOUT + _UNIFORM + r"[iu]?image\w*\s+(?P<name>\w+)", re.M),
    "buffer": re.compile(_LAYOUT + r"(?P<before>" + _WORDS + r")buffer\s+(?P<name>\w+)\s*\{", re.M),
    "uniform block": re.compile(_LAYOUT + _UNIFORM + r"(?P<name>\w+)\s*\{", re.M),
}
_UNIT_WORD = {"sampler": "texture unit", "image": "image unit", "buffer": "storage buffer binding",
              "uniform block": "uniform buffer binding"}
FRAME_BLOCK, FRAME_BINDING = "Frame", 0   # lib/frame.glsl's block (atmos.frame_constants): its binding is its alone
_MESSAGES = (re.compile(r"^(?P<where>\d+):(?P<line>\d+)\(\d+\):\s*(?P<text>.*)$"),       # Mesa: 0:14(7): error: ...
             re.compile(r"^(?P<where>\d+)\((?P<line>\d+)\)\s*:\s*(?P<text>.*)$"),         # NVIDIA: 0(14) : error C0000: ...
             re.compile(r"^(?P<kind>ERROR|WARNING):\s*(?P<where>[^:\s]+):(?P<line>\d+):\s*(?P<text>.*)$"))  # glslang, AMD


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


@dataclass(frozen=True)
class GlslSource:
    """One shader stage as the driver gets it: ``text`` (includes expanded, defines added, no
    ``#line`` directives) and ``origins[i]``, the (file name, line) that line ``i + 1`` of ``text``
    came from (``None`` for the added ``#define`` lines)."""
    text: str
    origins: tuple

    @property
    def files(self) -> list[str]:
        """The file names in the order they were first included, the stage's own file first."""
        return list(dict.fromkeys(o[0] for o in self.origins if o is not None))

    def where(self, line: int) -> str:
        """How errors name line ``line`` (1-based) of :attr:`text`: ``shaders/lib/x.glsl:14``."""
        origin = self.origins[line - 1] if 1 <= line <= len(self.origins) else None
        if origin is None:
            return f"<{self.files[0]}, line {line} as compiled>" if self.files else f"<line {line}>"
        return f"{_display(origin[0])}:{origin[1]}"


def load_source(name: str, defines: dict | None = None) -> GlslSource:
    """Shader ``name`` as one GLSL text: includes expanded in place, ``defines`` added after ``#version``.

    No ``#line`` directive is emitted (NVIDIA rejects source-string numbers beyond the strings it was
    given, and a bare ``#line`` would make every file's lines collide); the returned
    :class:`GlslSource` maps each line back to its file and line instead.
    """
    lines: list[str] = []
    origins: list = []

    def expand(file: str, stack: tuple[str, ...]) -> None:
        if file in stack:
            raise ShaderError(f"{_display(file)}: #include cycle: {' -> '.join(stack + (file,))}")
        shown, source = _locate(file)
        for number, line in enumerate(source.splitlines(), start=1):
            if _VERSION.match(line):
                if stack:
                    raise ShaderError(f"{shown}:{number}: an included file must not have #version")
                lines.append(line)
                origins.append((file, number))
                for key, value in (defines or {}).items():
                    lines.append(f"#define {key} {value}")
                    origins.append(None)
                continue
            match = _INCLUDE.match(line)
            if match:
                try:
                    expand(match.group(1), stack + (file,))
                except ShaderError as error:
                    if "shader file not found" not in str(error) or " (included from " in str(error):
                        raise
                    raise ShaderError(f"{error} (included from {shown}:{number})") from None
            else:
                lines.append(line)
                origins.append((file, number))

    expand(name, ())
    if not lines or not _VERSION.match(lines[0]):
        raise ShaderError(f"{_display(name)}:1: the first line must be a #version directive")
    return GlslSource("\n".join(lines) + "\n", tuple(origins))


def compiler_message(raw: str) -> tuple[str, int, str] | None:
    """``(where, line, message)`` of one compiler output line that names a line, the message led by its
    kind (``error: ...``); None for any other line. Understands Mesa's ``0:14(7): error: ...``,
    NVIDIA's ``0(14) : error C0000: ...`` and the ``ERROR: 0:14: ...`` of glslang and AMD's driver;
    ``where`` is the source-string number, or the file glslang names while linking."""
    raw = raw.strip()
    for pattern in _MESSAGES:
        match = pattern.match(raw)
        if match:
            kind = match.groupdict().get("kind")
            return match["where"], int(match["line"]), f"{kind.lower()}: {match['text']}" if kind else match["text"]
    return None


def located_messages(text: str, source: GlslSource) -> list[str]:
    """The compiler's messages in ``text`` that name a line, as ``<file>:<line>: <message>``."""
    return [f"{source.where(found[1])}: {found[2]}" for found in map(compiler_message, text.splitlines()) if found]


def explain(error: Exception, stages: dict[str, GlslSource]) -> ShaderError:
    """Turn a moderngl compile/link error into a ShaderError naming ``<file>:<line>`` (the real file)."""
    text = str(error)
    kind = "link" if "Linker" in text else "compile"
    stage = next((s for s in stages if s in text), None)
    messages = located_messages(text, stages[stage]) if stage else []
    if not messages:
        names = ", ".join(_display(s.files[0]) for s in stages.values())
        messages = [f"{names}: " + " ".join(l.strip() for l in text.splitlines() if l.strip())]
    return ShaderError(f"GLSL {kind} failed:\n" + "\n".join(messages))


def load_stages(stages: dict[str, str], defines: dict | None = None) -> dict[str, GlslSource]:
    """:func:`load_source` of each shader file name keyed by moderngl stage name (``vertex_shader``,
    ``fragment_shader``, ``geometry_shader``, or ``compute_shader`` alone)."""
    return {stage: load_source(name, defines) for stage, name in stages.items()}


def compile_program(ctx: moderngl.Context, sources: dict[str, GlslSource]):
    """Compile loaded stages into a moderngl program (a compute shader for ``compute_shader``): the
    internal of :meth:`GpuContext.program <atmos.gpu.GpuContext.program>`, which caches and
    releases what this makes (everything else asks the GpuContext)."""
    try:
        if "compute_shader" in sources:
            program = ctx.compute_shader(sources["compute_shader"].text)
        else:
            program = ctx.program(**{stage: src.text for stage, src in sources.items()})
    except moderngl.Error as error:
        raise explain(error, sources) from None
    try:
        check_units(program, sources)
    except ShaderError:
        program.release()
        raise
    return program


def check_units(program, sources: dict[str, GlslSource]) -> None:
    """Every sampler, image, storage block and uniform block the program uses declares its unit
    (``layout(binding = N)``: the one place a unit is written; Python binds by name,
    :mod:`atmos.gpu.uniforms`), and no two of a kind share one, nor any other uniform block the frame
    block's binding 0 (``lib/frame.glsl``): a ShaderError naming both declarations otherwise. Keeps each
    image's unit and declared access (readonly, writeonly or both) in ``program.extra["images"]`` for
    ``bind_images``, and the storage blocks it may write (not ``readonly``) in ``program.extra["written"]``
    for ``bind_buffers``."""
    images: dict[str, tuple[int, bool, bool]] = {}
    written: set[str] = set()
    for kind, pattern in _BINDINGS.items():
        seen: dict[int, tuple[str, str]] = {}
        for src in sources.values():
            for match in pattern.finditer(src.text):
                name = match.group("name")
                if name not in program:
                    continue
                where = src.where(src.text.count("\n", 0, match.start()) + 1)
                binding = re.search(r"\bbinding\s*=\s*(\w+)", match.group("layout") or "")
                if not binding:
                    raise ShaderError(f"{where}: {kind} {name} needs layout(binding = N): its {_UNIT_WORD[kind]}")
                member = program[name]
                if kind == "image":          # (an image uniform's value does not read back on every driver)
                    units = _constant(binding.group(1), src.text, where)
                else:
                    units = member.binding if kind in ("buffer", "uniform block") else member.value   # a sampler array: its units
                if kind == "uniform block" and units == FRAME_BINDING and name != FRAME_BLOCK:
                    raise ShaderError(f"{where}: uniform block {name} is at {_UNIT_WORD[kind]} {FRAME_BINDING}, the "
                                      f"frame block's (lib/frame.glsl): give it another binding")
                for unit in units if isinstance(units, list) else [units]:
                    if unit in seen and seen[unit][0] != name:
                        raise ShaderError(f"{where}: {kind} {name} and {seen[unit][0]} ({seen[unit][1]}) share "
                                          f"{_UNIT_WORD[kind]} {unit}")
                    seen[unit] = (name, where)
                if kind == "image":
                    words = (match.group("before") + match.group("after")).split()
                    images[name] = (units, "writeonly" not in words, "readonly" not in words)
                elif kind == "buffer" and "readonly" not in match.group("before").split():
                    written.add(name)
    program.extra = {"images": images, "written": frozenset(written), "hazards": hazards_of(program.ctx)}


def _constant(word: str, text: str, where: str) -> int:
    """An integer literal, or a name ``#define``d as one in ``text``."""
    for _ in range(8):
        if word.isdigit():
            return int(word)
        define = re.search(rf"^\s*#define\s+{word}\s+(\w+)\s*$", text, re.M)
        if not define:
            break
        word = define.group(1)
    raise ShaderError(f"{where}: layout(binding = {word}) must be an integer (or a name #defined as one)")
