#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# The whole GPU check in one command of at most ~10 minutes, for a GPU machine that runs one
# command at a time and returns a few files:
#
#   OUT=DIR bash tools/gpu_check_all.sh BUNDLE [JIT_CACHE]
#
# (from a checkout with build/deme_shim/ built, or g++ on the GPU machine; BUNDLE from
# tools/deme_bundle.sh, JIT_CACHE the jit-cache.tar.xz of an earlier run).
# 1. DIR/check: the contract rows, drag, tilt and the tilt's spread (tools/gpu_check.sh),
#    their solvers compiling side by side: ~160-280 s when the force model changed since
#    JIT_CACHE was made, seconds of compiling when it did not.
# 2. DIR/bench: the bench with the GPU to itself (20 rounds of 500 steps: adaptive detection,
#    every 20 steps with a fixed bin size, and the A/A control of the engine's model against
#    itself): ~125 s on a warm cache, plus up to ~160 s for a cold compile of the stick-slip
#    model's bench kernels (the kernels of step 1 are other ones).
# Leaves 8 files: each step's summary.txt and results.json, the drag's and tilt's time series
# (check/*_deme.csv.gz), logs.txt (the GPU's name and both steps' parts.log) and the last
# jit-cache.tar.xz (which holds both steps' kernels: JIT_CACHE of the next run).
set -uo pipefail
cd "$(dirname "$0")/.."
BUNDLE=${1:?usage: OUT=DIR bash tools/gpu_check_all.sh BUNDLE [JIT_CACHE]}
CACHE=${2:-}
OUT=${OUT:?set OUT to the folder for the files}
OUT="$OUT/check" bash tools/gpu_check.sh "$BUNDLE" "$CACHE" --parts contract drag tilt spread \
    --deadline 280 --tilt-every 50
first=$?
[ "$first" -eq 2 ] && exit 2  # no engine here (gpu_check.sh said why): the bench cannot run either
# the bundle stays unpacked and the compiled kernels stay in gpu_check.sh's work folder: no cache to give
OUT="$OUT/bench" bash tools/gpu_check.sh "$BUNDLE" "" --parts bench --rounds 20 --bench-steps 500 \
    --settle-steps 6000 --cd-freq 20 --control --deadline 290
second=$?
cat "$OUT/check/gpu.txt" "$OUT/check/parts.log" "$OUT/bench/parts.log" > "$OUT/logs.txt" 2>/dev/null
rm -f "$OUT/check/jit-cache.tar.xz" "$OUT"/{check,bench}/{gpu.txt,parts.log}
ls -la "$OUT" "$OUT/check" "$OUT/bench"
echo "gpu_check_all: check exit $first, bench exit $second"
exit $(( first > second ? first : second ))
