#!/usr/bin/env bash
# The install of the C library (scripts/install-c.sh) tried as a consumer would, in the C part of
# the README's test command: install the test build (already built by scripts/test-c.sh) into a
# temporary prefix, check the SONAME, then build examples/install/consumer.c against it
#   * with pkg-config: `gonio` (shared; the program records NEEDED libgonio.so.0.MINOR and runs
#     with the prefix's lib on LD_LIBRARY_PATH) and `gonio-static` (no libgonio NEEDED);
#   * with CMake: find_package(gonio CONFIG REQUIRED), gonio::gonio (runs through CMake's rpath,
#     no LD_LIBRARY_PATH) and gonio::gonio_static;
# and run each. CMake comes from PATH or, where the machine has none, the `cmake` wheel from PyPI
# in the package's virtual environment ($GONIO_VENV, default .venv); without either the CMake half
# is SKIPPED with the reason. The prefix is removed at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"
bash scripts/install-c.sh "$prefix" --profile test
so="$(cd "$prefix/lib" && ls libgonio.so.*.*.*)"
soname="$(readelf -d "$prefix/lib/$so" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')"
echo "test-install: $so has SONAME ${soname:-<none>}"
[ -n "$soname" ] && [ -e "$prefix/lib/$soname" ] || { echo "test-install: FAILED: no SONAME link"; exit 1; }
src="$root/crates/gonio-capi/examples/install"

echo "== pkg-config: gonio (shared) and gonio-static"
export PKG_CONFIG_PATH="$prefix/lib/pkgconfig"
# shellcheck disable=SC2046
cc -std=c99 -O1 -Wall -Wextra -Werror $(pkg-config --cflags gonio) "$src/consumer.c" \
  $(pkg-config --libs gonio) -lm -o "$tmp/pc_shared"
readelf -d "$tmp/pc_shared" | grep -q "NEEDED.*\[$soname\]" \
  || { echo "test-install: FAILED: pc_shared does not need $soname"; exit 1; }
LD_LIBRARY_PATH="$prefix/lib" "$tmp/pc_shared"
# shellcheck disable=SC2046
cc -std=c99 -O1 -Wall -Wextra -Werror $(pkg-config --cflags gonio-static) "$src/consumer.c" \
  $(pkg-config --libs gonio-static) -lm -o "$tmp/pc_static"
if readelf -d "$tmp/pc_static" | grep -q "NEEDED.*libgonio"; then
  echo "test-install: FAILED: pc_static needs libgonio"; exit 1
fi
env -u LD_LIBRARY_PATH "$tmp/pc_static"

echo "== CMake: find_package(gonio CONFIG REQUIRED)"
cmake_bin="$(command -v cmake || true)"
if [ -z "$cmake_bin" ]; then
  venv="${GONIO_VENV:-$root/.venv}"
  if [ -x "$venv/bin/python" ] && "$venv/bin/python" -m pip install -q --disable-pip-version-check cmake; then
    cmake_bin="$venv/bin/cmake"
  fi
fi
if [ -z "$cmake_bin" ] || [ ! -x "$cmake_bin" ]; then
  echo "test-install: SKIPPED the CMake consumer: no cmake on PATH and the cmake wheel could not be installed"
  exit 0
fi
"$cmake_bin" --version | head -n 1
"$cmake_bin" -S "$src" -B "$tmp/build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >/dev/null
"$cmake_bin" --build "$tmp/build" >/dev/null
env -u LD_LIBRARY_PATH "$tmp/build/consumer_shared"
env -u LD_LIBRARY_PATH "$tmp/build/consumer_static"
# A request for another 0.x minor version is refused by the version file.
sed 's/find_package(gonio 0.1 CONFIG REQUIRED)/find_package(gonio 0.2 CONFIG REQUIRED)/' \
  "$src/CMakeLists.txt" > "$tmp/other.txt"
mkdir -p "$tmp/other" && cp "$tmp/other.txt" "$tmp/other/CMakeLists.txt" && cp "$src/consumer.c" "$tmp/other/"
if "$cmake_bin" -S "$tmp/other" -B "$tmp/build2" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null 2>&1; then
  echo "test-install: FAILED: find_package(gonio 0.2) accepted gonio 0.1"; exit 1
fi
echo "test-install: ok"
