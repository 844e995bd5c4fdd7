# Sourced by run.sh and run_tests.sh ON THE GPU MACHINE, in the repository root of a copy of the
# working tree that carries .gl/ and .whl/ (made by prepare.sh): after it, `python3` imports atmos
# from the tree (no build, no install) in this process and in every child process (pytest-xdist
# workers, `python3 -m atmos`), with atmos's entry points registered.
#   1. the GL loader debs are unpacked into / when the machine has no libEGL/libOpenGL;
#   2. EGL is pointed at the NVIDIA driver when its vendor file exists;
#   3. the wheels go into $ATMOS_SITE (default /tmp/atmos-site), with a sitecustomize.py and an
#      atmos dist-info written there by tree_import.py --site;
#   4. PYTHONPATH, ATMOS_TREE and ATMOS_HEADLESS are exported.
PY=${PYTHON:-python3}
if [ -d .gl ] && ! { ldconfig -p | grep -q 'libEGL.so.1 ' && ldconfig -p | grep -q 'libOpenGL.so.0 '; }; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
vendor=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
[ -f "$vendor" ] && export __EGL_VENDOR_LIBRARY_FILENAMES="$vendor"
ATMOS_SITE=${ATMOS_SITE:-/tmp/atmos-site}
$PY -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target "$ATMOS_SITE" .whl/*.whl
$PY benchmarks/tree_import.py --site "$ATMOS_SITE" .
export PYTHONPATH="$ATMOS_SITE"${PYTHONPATH:+:$PYTHONPATH} ATMOS_TREE="$PWD" ATMOS_HEADLESS=1 PYTHONUNBUFFERED=1
export PATH="$ATMOS_SITE/bin:$PATH"
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv 2>/dev/null || true
