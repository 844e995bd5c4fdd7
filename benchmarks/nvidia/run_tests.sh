#!/usr/bin/env bash
# Run ON THE GPU MACHINE, in the repository root of a copy of the working tree that carries .gl/
# and .whl/ (made here by benchmarks/nvidia/prepare.sh): the whole test suite in parallel, then the
# GPU suite, in one command:
#   bash benchmarks/nvidia/run_tests.sh --out DIR [--workers N] [--no-suite] [-- PYTEST_ARGS...]
# DIR receives tests.log (pytest's report, failures in full), tests.xml (JUnit) and, unless
# --no-suite, gpu_suite.md/.json. pytest and pytest-xdist come from .whl with plugin autoloading
# off, so plugins of the machine's own pytest cannot clash with them. Tests that need what the
# machine lacks (an X server for the window tests) are skipped with the reason in the report.
set -uo pipefail
cd "$(dirname "$0")/../.."
out=out/nvidia workers=$(( $(nproc) < 16 ? $(nproc) : 16 )) suite=1 args=()
while [ $# -gt 0 ]; do
    case "$1" in
        --out) out=$2; shift 2 ;;
        --workers) workers=$2; shift 2 ;;
        --no-suite) suite=0; shift ;;
        --) shift; args=("$@"); break ;;
        *) echo "run_tests.sh: unknown argument $1 (--out DIR, --workers N, --no-suite, -- PYTEST_ARGS)" >&2; exit 2 ;;
    esac
done
mkdir -p "$out"
set -e
source benchmarks/nvidia/env.sh
set +e
export PYTEST_DISABLE_PLUGIN_AUTOLOAD=1
python3 -m pytest -p xdist.plugin -p no:cacheprovider -n "$workers" -q -rfEs --junitxml="$out/tests.xml" \
    "${args[@]}" 2>&1 | tee "$out/tests.log"
tests=${PIPESTATUS[0]}
echo "run_tests.sh: pytest exited $tests; $(tail -n 1 "$out/tests.log")"
if [ "$suite" = 1 ]; then
    python3 benchmarks/gpu_suite.py --out "$out"
    suite_rc=$?
    echo "run_tests.sh: gpu_suite exited $suite_rc"
    [ "$tests" = 0 ] && tests=$suite_rc
fi
exit "$tests"
