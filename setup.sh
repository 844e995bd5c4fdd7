#!/usr/bin/env bash
# Sets atmos up on a fresh machine: OpenGL/EGL system libraries if missing, then .venv with atmos
# installed in editable mode with its test and benchmark tools.
set -euo pipefail
cd "$(dirname "$0")"

if ! ldconfig -p 2>/dev/null | grep -q 'libEGL.so.1' || ! ls /usr/lib/*/dri/swrast_dri.so >/dev/null 2>&1; then
    echo "setup: installing Mesa's EGL and software OpenGL (libegl1 libegl-mesa0 libgl1-mesa-dri libgl1)"
    SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libegl1 libegl-mesa0 libgl1-mesa-dri libgl1 >/dev/null
fi

# A virtual X server and xdotool let the tests drive the window path on a machine without a screen;
# Khronos's reference GLSL compiler checks every shader the tests compile (atmos/gpu/portability.py).
if ! command -v Xvfb >/dev/null || ! command -v xdotool >/dev/null || ! command -v glslangValidator >/dev/null; then
    if command -v apt-get >/dev/null; then
        echo "setup: installing xvfb, xdotool (window tests) and glslang-tools (the GLSL portability check)"
        SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"
        $SUDO apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq xvfb xdotool glslang-tools >/dev/null || true
    fi
fi

python3 -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e '.[dev]'
.venv/bin/atmos info > .venv/gl-info.txt && head -3 .venv/gl-info.txt
echo "setup: done. Run a demo with .venv/bin/atmos demo, the tests with .venv/bin/python -m pytest"
