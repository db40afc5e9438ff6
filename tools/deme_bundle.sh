#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# DEM-Engine for a GPU machine without network: the `deme` 3.0.19 wheel and the CUDA 12.8
# wheels it compiles with (runtime, NVRTC, nvcc's and cuRAND's headers, CCCL), unpacked into
# one site/ folder and packed as OUT_DIR/deme-bundle.tar.xz (~39 MB) for tools/gpu_check.sh.
# Left out: the wheel's static library and demo meshes, NVRTC's alternative builtins.
# Usage: tools/deme_bundle.sh OUT_DIR   (needs pip and PyPI; a few minutes, mostly xz)
set -euo pipefail
OUT=$(readlink -f "${1:?usage: deme_bundle.sh OUT_DIR}")
mkdir -p "$OUT"
WHEELS=$(mktemp -d)
SITE=$(mktemp -d)/site
mkdir -p "$SITE"
python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
    --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 --platform manylinux_2_17_x86_64 \
    --platform manylinux2014_x86_64 -d "$WHEELS" \
    deme==3.0.19 nvidia-cuda-runtime-cu12==12.8.90 nvidia-cuda-nvrtc-cu12==12.8.93 \
    nvidia-cuda-cccl-cu12==12.8.90 nvidia-cuda-nvcc-cu12==12.8.93 nvidia-curand-cu12==10.3.9.90
cd "$SITE"
unzip -oq "$WHEELS"/deme-*.whl -x 'lib64/libsimulator_multi_gpu.a' 'share/DEME/data/mesh/*'
unzip -oq "$WHEELS"/nvidia_cuda_runtime*.whl
unzip -oq "$WHEELS"/nvidia_cuda_cccl*.whl
unzip -oq "$WHEELS"/nvidia_cuda_nvrtc*.whl -x '*alt.so*'
unzip -oq "$WHEELS"/nvidia_cuda_nvcc*.whl 'nvidia/cuda_nvcc/include/*' 'nvidia_cuda_nvcc*dist-info/*'
unzip -oq "$WHEELS"/nvidia_curand*.whl 'nvidia/curand/include/*' 'nvidia_curand*dist-info/*'
cd ..
tar -cf - site | xz -T0 -9 > "$OUT/deme-bundle.tar.xz"
ls -la "$OUT/deme-bundle.tar.xz"
