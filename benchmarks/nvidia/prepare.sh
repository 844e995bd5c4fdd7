#!/usr/bin/env bash
# Run HERE (a Debian/Ubuntu x86-64 machine with apt and pip that reach their registries), in the
# repository root, once: fetches what a GPU machine without a package index needs to run
# benchmarks/gpu_suite.py, into two folders that git ignores:
#   .gl/   the GL loader debs (libglvnd's EGL/GL dispatch; the NVIDIA driver supplies the rest)
#   .whl/  wheels for what the GPU machine's python3 (3.12) lacks: moderngl, glcontext, esper, pyglet
# Then send the tree with .gl and .whl to the GPU machine and run benchmarks/nvidia/run.sh there.
set -euo pipefail
cd "$(git rev-parse --show-toplevel)"
for folder in /.gl/ /.whl/; do
    grep -qxF "$folder" .git/info/exclude 2>/dev/null || echo "$folder" >> .git/info/exclude
done
mkdir -p .gl .whl /tmp/amd64/partial
o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
apt-get $o update -qq
(cd .gl && apt-get $o download libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
PY=${PYTHON:-python3}
$PY -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
    --platform manylinux_2_28_x86_64 --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 \
    --platform manylinux1_x86_64 -d .whl moderngl==5.13.0 glcontext==3.1.0
$PY -m pip download -q --no-deps --only-binary=:all: -d .whl esper==3.9 pyglet==2.1.19
ls -l .gl .whl
