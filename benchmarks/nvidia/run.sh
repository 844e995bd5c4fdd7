#!/usr/bin/env bash
# Run ON THE GPU MACHINE, in the repository root of a copy of the working tree that carries .gl/
# and .whl/ (made here by benchmarks/nvidia/prepare.sh): unpacks the GL loaders, points EGL at the
# NVIDIA driver, installs the wheels into /tmp/site, imports atmos from the tree (no install) and
# runs the whole GPU suite. Arguments go to gpu_suite.py (e.g. --out "$OUT", --only clouds sunset).
set -euo pipefail
cd "$(dirname "$0")/../.."
for f in .gl/*.deb; do dpkg -x "$f" /; done
ldconfig
vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$vendor"
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl
export PYTHONPATH=/tmp/site${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1 ATMOS_HEADLESS=1
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv 2>/dev/null || true
exec python3 benchmarks/tree_import.py . benchmarks/gpu_suite.py "$@"
