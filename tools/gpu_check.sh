#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The DEM-Engine check, on a machine with an NVIDIA GPU and python3 3.12 (no network needed):
#
#   bash tools/gpu_check.sh BUNDLE [JIT_CACHE] [deme_gpu_check.py options]
#
# BUNDLE: deme-bundle.tar.xz, DEM-Engine 3.0.19 (PyPI deme) with the CUDA 12.8 runtime, NVRTC
# and headers it compiles with (~39 MB; made where PyPI can be reached by tools/deme_bundle.sh). JIT_CACHE: a jit-cache.tar.xz an earlier run left in $OUT (its
# compiled kernels: a second run skips minutes of compiling), or "" for none.
# Unpacks the bundle under $TMPDIR/gpu_check (/tmp by default), links its share/, include/ and lib64/ into the
# interpreter's purelib folder (DEM-Engine looks for its kernel sources there), then runs
# tools/deme_gpu_check.py: the contract rows on the GPU against the CPU shim, drag and tilt
# against pyref, and the bench (stick-slip against the engine's own frictional Hertz-Mindlin).
# Writes $OUT/summary.txt, results.json, parts.log, gpu.txt and jit-cache.tar.xz.
set -uo pipefail
cd "$(dirname "$0")/.."
BUNDLE=${1:?usage: gpu_check.sh BUNDLE [JIT_CACHE] [options]}
CACHE=${2:-}
shift $(( $# >= 2 ? 2 : 1 ))
OUT=${OUT:-$PWD/gpu_check_out}
W=${TMPDIR:-/tmp}/gpu_check
mkdir -p "$OUT" "$W"
export OUT PYTHONUNBUFFERED=1
t0=$(date +%s)
if [ ! -d "$W/site/deme" ]; then
    xz -T0 -dc "$BUNDLE" | tar -x -C "$W" || { echo "gpu_check: cannot unpack $BUNDLE"; exit 2; }
fi
PURE=$(python3 -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")
for d in share include lib64; do
    if [ -e "$PURE/$d" ] && [ ! -L "$PURE/$d" ]; then
        for e in "$W/site/$d"/*; do ln -sfn "$e" "$PURE/$d/"; done
    else
        ln -sfn "$W/site/$d" "$PURE/$d"
    fi
done
if [ -n "$CACHE" ] && [ -f "$CACHE" ]; then
    xz -T0 -dc "$CACHE" | tar -x -C "$W" && echo "gpu_check: JIT cache from $CACHE"
fi
export PYTHONPATH="$W/site:$PWD${PYTHONPATH:+:$PYTHONPATH}"
echo "gpu_check: unpacked in $(( $(date +%s) - t0 )) s"
{ nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader; python3 --version;
  python3 -c "import deme; print('deme', deme.__version__)"; } 2>&1 | tee "$OUT/gpu.txt"
python3 -c "import deme" 2>/dev/null || { echo "gpu_check: import deme fails"; exit 2; }
# the force model's CPU shim (drag and tilt bounds, tools/deme_plane_emulation.py): carried in
# build/deme_shim/ from a machine that ran the tests, else built here with g++
python3 -c "from stickslip.contract import deme_shim; print('gpu_check: CPU shim', deme_shim.library_path())" 2>&1 | tail -1
python3 tools/deme_gpu_check.py --out "$OUT" --cache "$W/jit" "$@"
status=$?
# the compiled kernels, for a rerun (files back from the machine: at most 16 MiB each)
(cd "$W" && tar -cf - jit | xz -T0 -6 > "$OUT/jit-cache.tar.xz")
[ "$(stat -c %s "$OUT/jit-cache.tar.xz")" -gt 16000000 ] && rm -f "$OUT/jit-cache.tar.xz"
echo "gpu_check: $(( $(date +%s) - t0 )) s in all"; ls -la "$OUT"
exit $status
