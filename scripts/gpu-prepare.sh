#!/usr/bin/env bash
# Prepares, here (where ../shared and the network are), what scripts/gpu-check.sh needs on a GPU
# machine without gonio, ../shared or network; docs/GPU.md. Fills (both ignored by git):
#
#   .gpudata/  float32 blobs of the contract cases (the example, split and Lambert; three corpus
#              files; a random sphere and a random hemisphere diagram; the timing grids 19 x 36 and
#              181 x 361), the environment maps of ../shared/data/envmaps as .hdr (their blobs
#              are rebuilt on the GPU machine and checked against the checksums recorded here),
#              the library's float32 reference outputs on 2^15 points per case (refs/*.npz:
#              sample's directions and pdf, pdf and invert at those directions), the light-tracing
#              reference, manifest.json. ~17 MB.
#   .whl/      the gonio wheel (target/python-wheel/gonio-*.whl, abi3, manylinux_2_35: built by
#              scripts/test-python.sh) and, for CPython 3.12 on manylinux x86_64, drjit 1.5.0 and
#              mitsuba 3.9.1 cut down to cuda_ad_rgb and the plugins the check loads (the full
#              mitsuba wheel, 62.6 MB, is more than the device tool carries). ~31 MB. The download:
#
#     python -m pip download --only-binary=:all: --no-deps --python-version 3.12 \
#       --implementation cp --platform manylinux_2_28_x86_64 mitsuba==3.9.1 drjit==1.5.0 \
#       -d target/gpu-wheel-cache
#
# Needs the project venv ($GONIO_VENV, default .venv: gonio, numpy), target/debug/libgonio_capi.so
# for the Lambert blob (cargo build -p gonio-capi; skipped without it). Prints the sizes: the
# two folders must stay under 60 MB together (the device tool carries 64 MiB).
# Options: --n-ref N (reference points per case), --no-wheels, --no-data.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${GONIO_VENV:-.venv}"
exec "$venv/bin/python" scripts/gpu_prepare.py "$@"
