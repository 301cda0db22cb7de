#!/usr/bin/env bash
# Device code proven without a device (docs/GPU.md, "Compiled here"): NVRTC compiles every CUDA
# source that includes crates/gonio-capi/include/gonio_device.h to PTX for compute_80 and
# compute_90, and ptxas assembles it for sm_80 / sm_90 (-v: registers, stack, spills per kernel):
# crates/gonio-capi/tests/device/kernels.cu (structure-of-arrays sample/pdf/invert/target, the
# light-tracing kernel of docs/GPU.md) and gonio.cuda's module (gonio/cuda.py). Then checks, on
# the host with `cc`, that gonio.cuda's device-side view builder gives gonio_device_view_init's
# view byte for byte. No GPU and no CUDA toolkit needed: NVRTC and ptxas come from the pip wheels
# nvidia-cuda-nvrtc and nvidia-cuda-nvcc (CUDA 13; the -cu12 wheels as a fallback), installed
# into the project venv ($GONIO_VENV, default .venv). Exit 1 on a compile error, 77 (skipped,
# with the reason) when the wheels cannot be had. ~15 s once the wheels are installed.
set -uo pipefail
cd "$(dirname "$0")/.."

venv="${GONIO_VENV:-.venv}"
py="$venv/bin/python"
if [ ! -x "$py" ]; then
  echo "test-device: SKIPPED: no Python venv at $venv (set GONIO_VENV)"
  exit 77
fi
check=crates/gonio-capi/tests/device/nvrtc_check.py

have_tools() {
  "$py" - <<'EOF'
import glob, os, site, sys
dirs = list(site.getsitepackages()) + sys.path
def has(pats):
    return any(glob.glob(os.path.join(d, p)) for d in dirs if d for p in pats)
ok = has(["nvidia/cu13/lib/libnvrtc.so.*", "nvidia/cuda_nvrtc/lib/libnvrtc.so.*"]) and \
     has(["nvidia/cu13/bin/ptxas", "nvidia/cuda_nvcc/bin/ptxas"])
sys.exit(0 if ok else 1)
EOF
}

if ! have_tools; then
  echo "test-device: installing NVRTC and ptxas from pip into $venv"
  if ! "$py" -m pip install -q --disable-pip-version-check --timeout 20 --retries 1 \
      'nvidia-cuda-nvrtc>=13,<14' 'nvidia-cuda-nvcc>=13,<14'; then
    echo "test-device: the CUDA 13 wheels failed; trying the CUDA 12 ones"
    "$py" -m pip install -q --disable-pip-version-check --timeout 20 --retries 1 \
      'nvidia-cuda-nvrtc-cu12>=12.4' 'nvidia-cuda-nvcc-cu12>=12.4' || true
  fi
  if ! have_tools; then
    echo "test-device: SKIPPED: pip could not install nvidia-cuda-nvrtc / nvidia-cuda-nvcc"
    exit 77
  fi
fi

echo "== gonio_device.h: NVRTC -> PTX -> ptxas (no GPU)"
"$py" "$check" --json target/device-ptxas.json || { echo "test-device: FAILED"; exit 1; }

echo "== gonio.cuda's device view builder against gonio_device_view_init (host, cc)"
"$py" crates/gonio-capi/tests/device/view_check.py
rc=$?
if [ "$rc" -eq 77 ]; then
  echo "test-device: SKIPPED the view check (see above)"
elif [ "$rc" -ne 0 ]; then
  echo "test-device: FAILED"
  exit 1
fi
echo "test-device: ok"
