#!/usr/bin/env bash
# The C ABI from C and C++ (docs/C_API.md): builds crates/gonio-capi (the test profile, opt-level 2,
# which `cargo test --workspace` has already built, so only the archive is linked), compiles the C
# examples (photometry and BRDF) and the C++ RAII example with the system cc/c++ against
# include/gonio.h and the static library, runs them (on corpus files; the BRDF example on a table
# it writes itself), then runs both again under valgrind (no error, no leak). Also tests the
# header-only sampler include/gonio_device.h against the library (examples/device_test.c).
# The corpus is $GONIO_CORPUS, else ../shared/data/photometry beside the repository.
# Whatever cannot run on this machine (no compiler, no valgrind, no corpus) is reported as SKIPPED.
set -euo pipefail
cd "$(dirname "$0")/.."

corpus="${GONIO_CORPUS:-../shared/data/photometry}"
if [ ! -d "$corpus/ies" ] || [ ! -d "$corpus/ldt" ]; then
  echo "test-c: SKIPPED: corpus not found at $corpus (set GONIO_CORPUS)"
  exit 77
fi
for tool in cc c++; do
  if ! command -v "$tool" >/dev/null; then
    echo "test-c: SKIPPED: no $tool on this machine"
    exit 77
  fi
done

cargo build --profile test --locked -p gonio-capi
lib=target/debug/libgonio_capi.a
inc=crates/gonio-capi/include
ex=crates/gonio-capi/examples
out=target/c-examples
mkdir -p "$out"
# What a static Rust library needs from the system on Linux.
libs=(-lpthread -ldl -lm)

cc -std=c11 -O1 -g -Wall -Wextra -Werror -pedantic -I "$inc" "$ex/example.c" "$lib" "${libs[@]}" \
  -o "$out/example_c"
cc -std=c11 -O1 -g -Wall -Wextra -Werror -pedantic -I "$inc" "$ex/brdf.c" "$lib" "${libs[@]}" \
  -o "$out/brdf_c"
# The header alone is C89 (C users may include it from C89 code).
printf '#include "gonio.h"\nint main(void) { return GONIO_OK; }\n' > "$out/c89.c"
cc -std=c89 -pedantic -Wall -Wextra -Werror -I "$inc" -c "$out/c89.c" -o "$out/c89.o"
c++ -std=c++17 -O1 -g -Wall -Wextra -Werror -pedantic -I "$inc" "$ex/example.cpp" "$lib" \
  "${libs[@]}" -pthread -o "$out/example_cpp"
# The header-only sampler include/gonio_device.h (docs/GPU.md): its test as C99 with
# -ffp-contract=off (the library's float32 kernels use no FMA), and the header alone as C++17.
cc -std=c99 -O2 -g -ffp-contract=off -Wall -Wextra -Werror -pedantic -I "$inc" \
  "$ex/device_test.c" "$lib" "${libs[@]}" -o "$out/device_test"
printf '%s\n' '#include "gonio_device.h"' \
  'int main() { GonioDeviceView v; float d[3] = {0, 0, 1};' \
  '  return gonio_device_view_init(&v, nullptr, 0) == GONIO_DEVICE_E_TRUNCATED &&' \
  '         gonio_device_target(&v, d) == 0.0f ? 0 : 1; }' > "$out/device_cpp.cpp"
c++ -std=c++17 -O1 -Wall -Wextra -Werror -pedantic -I "$inc" "$out/device_cpp.cpp" \
  -o "$out/device_cpp"
"$out/device_cpp"

# A type C IES file with all 360° of planes, a quadrant-symmetric EULUMDAT file with two lamp sets,
# and a type B IES file (resampled to type C by the library).
files=(
  "$corpus/ies/lm63_2002_lithonia_area_full_h0_360.ies"
  "$corpus/ldt/isym4_two_lamp_sets_144x73.ldt"
  "$corpus/ies/lm63_2002_lithonia_type_b_flood_quadrant.ies"
)
# gonio.hpp covers the whole C ABI: every function gonio.h declares is called in it.
missing=()
while read -r f; do
  grep -q "\b$f(" "$inc/gonio.hpp" || missing+=("$f")
done < <(grep -o '^[A-Za-z].* \*\?gonio_[a-z0-9_]*(' "$inc/gonio.h" | sed 's/.*\(gonio_[a-z0-9_]*\)(/\1/' | sort -u)
if [ "${#missing[@]}" -gt 0 ]; then
  echo "test-c: FAILED: gonio.hpp does not wrap: ${missing[*]}"
  exit 1
fi
echo "test-c: gonio.hpp wraps every function of gonio.h ($(grep -c '^[A-Za-z].* \*\?gonio_[a-z0-9_]*(' "$inc/gonio.h") declarations)"
echo "== C example"
"$out/example_c" "${files[@]}"
echo "== C++ example"
"$out/example_cpp" "${files[0]}"
echo "== C BRDF example (writes and reads its own analytic JSON table)"
"$out/brdf_c" "$out"
# gonio_device.h against the library's float32 batches, point for point: the example (10^6
# points of the square, both sphere layouts), 12 random JSON diagrams (10^6 points each;
# split and Lambert sphere, hemisphere), every corpus file (10^6 points each), the environment
# maps of $GONIO_ENVMAPS (default ../shared/data/envmaps; 10^6 points each), after the refusals
# of broken blobs. One summary line per input kind with
# the fractions of bit-identical results.
envmaps="${GONIO_ENVMAPS:-../shared/data/envmaps}"
env_files=()
if compgen -G "$envmaps/*.hdr" >/dev/null; then
  env_files=("$envmaps"/*.hdr)
else
  echo "test-c: SKIPPED the environment maps of gonio_device.h: none at $envmaps"
fi
echo "== gonio_device.h against the library"
"$out/device_test" -n 1000000 -f 1000000 -e 1000000 "$corpus"/ies/*.ies "$corpus"/ldt/*.ldt \
  ${env_files[@]+"${env_files[@]}"}
# The same test compiled as C++17 (the header and the test are valid C++ too), on fewer points.
c++ -std=c++17 -O2 -ffp-contract=off -Wall -Wextra -Werror -pedantic -I "$inc" \
  -x c++ "$ex/device_test.c" -x none "$lib" "${libs[@]}" -pthread -o "$out/device_test_cpp"
echo "== gonio_device.h against the library, compiled as C++17"
"$out/device_test_cpp" -n 100000 -f 100000 -e 100000 "${files[@]}" \
  ${env_files[@]+"${env_files[0]}"}

if command -v valgrind >/dev/null; then
  # One file each (valgrind runs ~50x slower); any memory error or definite/indirect leak fails
  # the run. "Possibly lost" blocks are not counted: they are the thread-local storage of the
  # rayon pool's worker threads (the library builds tables in parallel), still running at exit.
  vg=(valgrind --quiet --error-exitcode=1 --leak-check=full --show-leak-kinds=definite,indirect
      --errors-for-leak-kinds=definite,indirect)
  echo "== C example under valgrind"
  "${vg[@]}" "$out/example_c" "${files[1]}" >/dev/null
  echo "== C++ example under valgrind"
  "${vg[@]}" "$out/example_cpp" "${files[1]}" >/dev/null
  echo "== C BRDF example under valgrind"
  "${vg[@]}" "$out/brdf_c" "$out" >/dev/null
  echo "== gonio_device.h refusing broken blobs under valgrind (no read outside a blob)"
  "${vg[@]}" "$out/device_test" --refusals-only >/dev/null
  echo "test-c: valgrind found no error and no leak"
else
  echo "test-c: SKIPPED the valgrind runs: valgrind is not installed"
fi
scripts/test-device.sh || [ $? -eq 77 ]  # NVRTC + ptxas on gonio_device.h (no GPU)
# The install (scripts/install-c.sh) found by CMake and pkg-config consumers, shared and static.
echo "== the installed library, found by pkg-config and CMake"
bash scripts/test-install.sh
echo "test-c: ok"
