#!/usr/bin/env bash
# The GPU check of gonio_device.h (docs/GPU.md, "Measured on an H200"), one command on a machine
# with one CUDA GPU, Python 3 with numpy and CuPy (cupy-cuda12x / cupy-cuda13x), run from the
# repository root with the folders scripts/gpu-prepare.sh fills here: .gpudata/ (blobs, the
# library's reference outputs, manifest) and .whl/ (gonio, drjit, mitsuba wheels; optional).
#
#   scripts/gpu-check.sh [--quick] [--n-time LOG2] [--reps R] [--no-mitsuba]
#
# Installs the wheels of .whl/ into $GONIO_GPU_SITE (default /tmp/site) with pip --target
# (--no-index --no-deps, one at a time; a wheel pip refuses for its platform tag is unzipped
# instead) unless they are there already, puts that folder on PYTHONPATH, then runs
# scripts/gpu_check.py: the contract on the device (directions within 1e-6, pdf within the
# float32 map's bound, invert within 1e-5; bit-identical fractions) for the example (split and
# Lambert), three corpus files, two random diagrams and the three environment maps; the
# light-tracing kernel against its reference; and the throughput table (2^24 points, best of 7
# CUDA-event times) of gonio, a pbrt-v4-style kernel and Mitsuba 3 (cuda_ad_rgb) on 19 x 36,
# 181 x 361, 1024 x 1024 and a 2048 x 1024 environment map, with the copy bandwidth. Writes
# $OUT/gpu-check.txt and $OUT/gpu-check.json when $OUT is set. About 1-2 minutes on an H200
# (NVRTC compiles about 10 s, the Mitsuba subprocess about 30 s); a hard limit of 290 s.
set -uo pipefail
cd "$(dirname "$0")/.."
py="${PYTHON:-python3}"
site="${GONIO_GPU_SITE:-/tmp/site}"

if [ ! -f .gpudata/manifest.json ]; then
  echo "gpu-check: .gpudata/manifest.json missing: run scripts/gpu-prepare.sh where ../shared is, and carry .gpudata"
  exit 2
fi
if compgen -G ".whl/*.whl" >/dev/null; then
  mkdir -p "$site"
  for w in .whl/*.whl; do
    pkg=$(basename "$w" | cut -d- -f1)
    if [ -d "$site/$pkg" ]; then
      continue
    fi
    if ! err=$("$py" -m pip install -q --disable-pip-version-check --no-index --no-deps \
        --target "$site" "$w" 2>&1); then
      echo "gpu-check: pip refused $(basename "$w") ($(echo "$err" | tail -1)); unzipping it instead"
      "$py" -m zipfile -e "$w" "$site" || echo "gpu-check: could not unzip $w"
    fi
  done
  export PYTHONPATH="$site${PYTHONPATH:+:$PYTHONPATH}"
else
  echo "gpu-check: no .whl/ folder: gonio, drjit and mitsuba come from the Python environment if at all"
fi
exec timeout 290 "$py" scripts/gpu_check.py "$@"
