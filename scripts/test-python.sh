#!/usr/bin/env bash
# The Python part of the README's test command (scripts/test-all.sh runs it): builds the package
# crates/gonio-py as a release abi3 wheel into a local virtual environment and runs its pytest suite,
# including Mitsuba 3's chi-square harness on gonio's samplers.
#
#   * the environment is $GONIO_VENV, default .venv/ at the repository root (git-ignored); it is
#     created if missing, with maturin, numpy, pytest, matplotlib and (if installable) mitsuba;
#   * Mitsuba's llvm_ad_rgb variant needs libLLVM: when none is found and we are root with apt-get,
#     libllvm19 is installed (set GONIO_NO_APT=1 to forbid that); otherwise its test is SKIPPED
#     with the reason, and everything else still runs;
#   * the CLI binary used to compare results is built with cargo (test profile, as cargo test has).
#
# Exit status: 0 all passed, 1 a failure, 77 the part could not run at all (no Python 3.9+).
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"

skip() { echo "SKIPPED (python): $*"; }

PY="${PYTHON:-python3}"
if ! command -v "$PY" >/dev/null 2>&1 || ! "$PY" -c 'import sys; assert sys.version_info >= (3, 9)' 2>/dev/null; then
  skip "no Python >= 3.9 found (set PYTHON); the Python package is not tested"
  exit 77
fi

venv="${GONIO_VENV:-$root/.venv}"
if [ ! -x "$venv/bin/python" ]; then
  echo "creating the virtual environment $venv"
  if ! "$PY" -m venv "$venv"; then
    skip "cannot create a virtual environment with $PY -m venv (Debian: apt-get install python3-venv)"
    exit 77
  fi
fi
vpy="$venv/bin/python"
pip_quiet=(-q --disable-pip-version-check)
"$vpy" -m pip install "${pip_quiet[@]}" -r crates/gonio-py/requirements-test.txt
if ! "$vpy" -c 'import mitsuba' 2>/dev/null; then
  if ! "$vpy" -m pip install "${pip_quiet[@]}" 'mitsuba>=3.5'; then
    skip "pip cannot install mitsuba here: Mitsuba's chi-square test will be skipped"
  fi
fi

# libLLVM for Mitsuba's llvm_ad_rgb variant (its scalar variants cannot run the chi2 harness).
find_llvm() {
  local f
  for f in /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 /usr/lib/x86_64-linux-gnu/libLLVM-1[4-9].so \
           /usr/lib/aarch64-linux-gnu/libLLVM.so.19.1 /usr/lib/aarch64-linux-gnu/libLLVM-1[4-9].so; do
    [ -e "$f" ] && { echo "$f"; return 0; }
  done
  return 1
}
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
  if ! llvm="$(find_llvm)" && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null \
      && [ -z "${GONIO_NO_APT:-}" ] && "$vpy" -c 'import mitsuba' 2>/dev/null; then
    echo "installing libllvm19 for Mitsuba's llvm variant (GONIO_NO_APT=1 forbids this)"
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libllvm19; } >/dev/null 2>&1 \
      || skip "apt-get install libllvm19 failed"
    llvm="$(find_llvm)" || true
  fi
  if [ -n "${llvm:-}" ]; then
    export DRJIT_LIBLLVM_PATH="$llvm"
  fi
fi

# The wheel: release, abi3, the manylinux2014 x86_64 wheel of scripts/build-wheels.sh (zig,
# glibc 2.17, checked by auditwheel) where ziglang installs, else the machine's own build; installed
# into a fresh virtual environment (it must import and sample there with numpy alone), then into
# the test environment.
wheels="$root/target/python-wheel"
rm -rf "$wheels"
if [ "$(uname -m)" = x86_64 ] && GONIO_VENV="$venv" bash scripts/build-wheels.sh --arch x86_64 --out "$wheels"; then
  rm -f "$wheels"/*.tar.gz
else
  echo "test-python: the manylinux2014 wheel could not be built (see above): testing the machine's own wheel"
  rm -rf "$wheels"
  "$venv/bin/maturin" build --release --locked -q -m crates/gonio-py/Cargo.toml -o "$wheels" \
    --interpreter "$vpy"
fi
whl="$(ls "$wheels"/gonio-*.whl | head -n 1)"
echo "test-python: the wheel under test: $(basename "$whl")"
fresh="$(mktemp -d)"
"$PY" -m venv "$fresh/venv"
"$fresh/venv/bin/python" -m pip install "${pip_quiet[@]}" "$whl"
(cd "$fresh" && "$fresh/venv/bin/python" -c '
import gonio, numpy as np
d, p = gonio.Sampler(gonio.example()).sample(np.array([[0.25, 0.75]]))
assert abs(np.linalg.norm(d[0]) - 1) < 1e-12 and p[0] > 0
print("test-python: the wheel installs and samples in a fresh environment: gonio", gonio.__version__)')
rm -rf "$fresh"
"$vpy" -m pip install "${pip_quiet[@]}" --force-reinstall --no-deps "$whl"
"$vpy" -c 'import gonio; print("gonio", gonio.__version__, "from", gonio.__file__)'

# The CLI, to compare the package's results with it: the test profile, which `cargo test
# --workspace` (run before this by scripts/test-all.sh) has already built, so nothing is rebuilt.
if [ -z "${GONIO_BIN:-}" ]; then
  cargo build -q --locked --profile test -p gonio-cli --bin gonio
  export GONIO_BIN="$root/target/debug/gonio"
fi

# The stubs and the annotated gonio.mitsuba, checked by mypy --strict on every example (and the
# typed API example run): a stub that drifts from the package fails here.
if "$vpy" -m pip install "${pip_quiet[@]}" mypy; then
  (cd "$(mktemp -d)" && "$vpy" -m mypy --strict --ignore-missing-imports --no-incremental \
    "$root"/examples/python/*.py)
  "$vpy" "$root/examples/python/typed_api.py"
else
  echo "SKIPPED (python): mypy cannot be installed here: the stubs are not type-checked"
fi

# Run from a scratch directory: Mitsuba writes chi2_data.py into the working directory on failure.
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
set +e
"$vpy" -m pytest "$root/crates/gonio-py/tests" -q -rs -p no:cacheprovider "$@"
rc=$?
set -e
if [ -f chi2_data.py ]; then
  mkdir -p "$root/target/python-test"
  cp chi2_data.py "$root/target/python-test/"
  echo "Mitsuba's tables of the failed test: target/python-test/chi2_data.py"
fi
exit "$rc"
