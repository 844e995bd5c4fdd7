"""A strict reference compiler over every program atmos builds, so that GLSL one driver tolerates and
the specification does not fails on every machine, not first on a user's GPU.

With ``ATMOS_GLSL_CHECK=1`` in the environment (the test suite sets it where the compiler is
installed; ``setup.sh`` installs Debian's ``glslang-tools``), every program that
:meth:`GpuContext.program <atmos.gpu.GpuContext.program>` compiles is also compiled and linked by
Khronos's ``glslangValidator``, stage by stage as the driver got it (includes expanded, defines
added). Its errors, and its warnings about ``#extension`` directives it does not know (a vendor's
extension), raise a :class:`~atmos.gpu.ShaderError` naming ``<file>:<line>``. A program it accepted
is remembered for the rest of the process.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

from atmos.gpu.shaders import GlslSource, ShaderError, compiler_message

ENV = "ATMOS_GLSL_CHECK"
COMPILER = "glslangValidator"
_SUFFIX = {"vertex_shader": "vert", "fragment_shader": "frag", "geometry_shader": "geom",
           "compute_shader": "comp"}
_ACCEPTED: set[bytes] = set()


def check_enabled() -> bool:
    """True when ``ATMOS_GLSL_CHECK=1``: GpuContext.program checks what it compiles."""
    return os.environ.get(ENV, "") == "1"


def check_program(sources: dict[str, GlslSource]) -> None:
    """Compile and link ``sources`` (moderngl stage name -> :class:`GlslSource`) with the reference
    compiler; a ShaderError naming file and line for what it refuses."""
    digest = hashlib.sha256("\0".join(f"{s}\0{sources[s].text}" for s in sorted(sources)).encode()).digest()
    if digest in _ACCEPTED:
        return
    compiler = shutil.which(COMPILER)
    if compiler is None:
        raise ShaderError(f"{ENV}=1 but {COMPILER} is not installed (Debian: apt-get install glslang-tools; "
                          f"setup.sh installs it); unset {ENV} to skip the portability check")
    with tempfile.TemporaryDirectory(prefix="atmos-glsl-") as folder:
        files = {}
        for stage, source in sources.items():
            path = Path(folder) / f"{stage}.{_SUFFIX[stage]}"
            path.write_text(source.text, encoding="utf-8")
            files[path.name] = source
        done = subprocess.run([compiler, "-l", *sorted(files)], cwd=folder, capture_output=True, text=True,
                              timeout=120)
    problems, current = [], None
    for line in (done.stdout + done.stderr).splitlines():
        if line.strip() in files:                      # a file's name before its messages ("ERROR: 0:14: ...")
            current = files[line.strip()]
            continue
        found = compiler_message(line)
        if found is None:
            continue
        name, number, message = found
        kind, text = message.split(": ", 1)
        if (kind == "warning" and "'#extension'" not in text) or text.startswith(("'' : compilation terminated",
                                                                                   "'' : missing #endif")):
            continue
        source = files.get(name, current)             # while linking: "ERROR: fragment_shader.frag:14: ..."
        problems.append(f"{source.where(number) if source is not None else name}: {message}")
    if done.returncode != 0 and not problems:
        problems = [line.strip() for line in (done.stdout + done.stderr).splitlines() if line.strip()]
    if problems:
        names = ", ".join(source.files[0] for source in sources.values())
        raise ShaderError(f"GLSL not portable ({COMPILER} refuses {names}):\n" + "\n".join(problems))
    _ACCEPTED.add(digest)
