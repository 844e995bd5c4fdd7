#!/usr/bin/env bash
# Run HERE (a Debian/Ubuntu x86-64 machine with apt and pip that reach their registries), in the
# repository root, once: fetches what a GPU machine without a package index needs to run the tests
# (run_tests.sh) and the GPU suite (run.sh), into two folders that git ignores:
#   .gl/   the GL loader debs (libglvnd's EGL/GL dispatch; the NVIDIA driver supplies the rest)
#   .whl/  wheels for what the GPU machine's Python lacks: moderngl, glcontext, esper, pyglet,
#          imageio with its ffmpeg (0.6: its wheel is half the size of the newest), tqdm, trimesh, and pytest with pytest-xdist (its own pytest's
#          plugins may clash with them: run_tests.sh loads only these)
# The GPU machine's Python is 3.12 (TARGET_PYTHON=3.11 prepares for a 3.11 one instead).
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"
for folder in /.gl/ /.whl/; do
    grep -qxF "$folder" .git/info/exclude 2>/dev/null || echo "$folder" >> .git/info/exclude
done
rm -rf .gl .whl
mkdir -p .gl .whl /tmp/amd64/partial
o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
apt-get $o update -qq
(cd .gl && apt-get $o download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
PY=${PYTHON:-python3}
target=(--only-binary=:all: --python-version "${TARGET_PYTHON:-3.12}" --implementation cp
        --platform manylinux_2_28_x86_64 --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64
        --platform manylinux1_x86_64 --platform manylinux2010_x86_64 --platform any)
$PY -m pip download -q --no-deps "${target[@]}" -d .whl moderngl==5.13.0 glcontext==3.1.0 \
    esper==3.9 pyglet==2.1.19 imageio==2.38.2 imageio-ffmpeg==0.6.0 tqdm==4.70.1 trimesh==5.2.0
$PY -m pip download -q "${target[@]}" -d .whl pytest==9.2.0 pytest-xdist==3.8.0   # with their dependencies
ls -l .gl .whl
du -sh .gl .whl
