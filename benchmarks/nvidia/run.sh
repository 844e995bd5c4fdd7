#!/usr/bin/env bash
# Run ON THE GPU MACHINE, in the repository root of a copy of the working tree that carries .gl/
# and .whl/ (made here by benchmarks/nvidia/prepare.sh): sets up the environment (env.sh) and runs
# the whole GPU suite. Arguments go to gpu_suite.py (e.g. --out "$OUT", --only clouds sunset).
set -euo pipefail
cd "$(dirname "$0")/../.."
source benchmarks/nvidia/env.sh
exec python3 benchmarks/gpu_suite.py "$@"
