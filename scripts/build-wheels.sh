#!/usr/bin/env bash
# The Python package's release artefacts (docs/PYTHON.md, "Wheels"): manylinux2014 (glibc 2.17)
# abi3 wheels for x86_64 and aarch64, cross-compiled and linked against glibc 2.17 by maturin's
# --zig (the `ziglang` wheel from PyPI), checked by `auditwheel show`, and the sdist, into
# target/wheels/.
#
# Usage: scripts/build-wheels.sh [--arch x86_64|aarch64|all] [--out DIR] [--check-sdist]
#   --arch: the wheels to build (default all; a target whose Rust standard library cannot be
#           installed with rustup is SKIPPED with the reason);
#   --out: the output folder (default target/wheels);
#   --check-sdist: also build a wheel from the sdist with pip (a full release build, minutes).
# The tools (maturin, ziglang, auditwheel) are installed into $GONIO_VENV (default .venv, created
# if missing). Exit status 0 when every requested artefact was built and checked.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"
arch="all"
out="$root/target/wheels"
check_sdist=0
while [ $# -gt 0 ]; do
  case "$1" in
    --arch) arch="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --check-sdist) check_sdist=1; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "build-wheels: unknown argument $1" >&2; exit 2 ;;
  esac
done
venv="${GONIO_VENV:-$root/.venv}"
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
vpy="$venv/bin/python"
"$vpy" -m pip install -q --disable-pip-version-check 'maturin>=1.7,<2' ziglang auditwheel
export PATH="$venv/bin:$PATH"
mkdir -p "$out"
targets=()
case "$arch" in
  x86_64) targets=(x86_64-unknown-linux-gnu) ;;
  aarch64) targets=(aarch64-unknown-linux-gnu) ;;
  all) targets=(x86_64-unknown-linux-gnu aarch64-unknown-linux-gnu) ;;
  *) echo "build-wheels: --arch x86_64, aarch64 or all" >&2; exit 2 ;;
esac
status=0
for t in "${targets[@]}"; do
  if ! rustup target list --installed 2>/dev/null | grep -qx "$t"; then
    if ! rustup target add "$t" >/dev/null 2>&1; then
      echo "build-wheels: SKIPPED $t: its Rust standard library is not installed and rustup cannot fetch it here"
      continue
    fi
  fi
  echo "== wheel for $t (manylinux2014, zig)"
  "$venv/bin/maturin" build --release --locked -q -m crates/gonio-py/Cargo.toml -o "$out" \
    --interpreter "$vpy" --zig --compatibility manylinux2014 --target "$t"
  whl="$(ls -t "$out"/gonio-*"${t%%-*}"*.whl | head -n 1)"
  report="$("$venv/bin/auditwheel" show "$whl" 2>&1)"
  if echo "$report" | tr -d '\n' | grep -q "manylinux_2_17_${t%%-*}"; then
    echo "build-wheels: $(basename "$whl"): auditwheel: consistent with manylinux_2_17_${t%%-*}"
  else
    echo "build-wheels: FAILED: $(basename "$whl") is not manylinux_2_17:"; echo "$report"; status=1
  fi
done
echo "== sdist"
"$venv/bin/maturin" sdist -m crates/gonio-py/Cargo.toml -o "$out" 2>&1 | tail -n 1
if [ "$check_sdist" = 1 ]; then
  sd="$(ls -t "$out"/gonio-*.tar.gz | head -n 1)"
  tmp="$(mktemp -d)"
  "$vpy" -m pip wheel -q --no-deps "$sd" -w "$tmp" && echo "build-wheels: the sdist builds: $(ls "$tmp")"
  rm -rf "$tmp"
fi
exit "$status"
