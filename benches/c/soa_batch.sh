#!/usr/bin/env bash
# Instructions per point of the C ABI's SoA batches (benches/c/soa_batch.c) under callgrind, one
# count per exported function (inclusive, --toggle-collect), for a static library LIB (default the
# release build of this tree). Instruction counts do not depend on the machine's load. (valgrind
# has no AVX-512: the kernels run on AVX2+FMA, or the portable backend where the CPU lacks it.)
#
#   cargo build --release -p gonio-capi && benches/c/soa_batch.sh [LIB] [FILE] [N]
set -euo pipefail
cd "$(dirname "$0")/../.."
lib=${1:-target/release/libgonio_capi.a}
file=${2:-${GONIO_CORPUS:-../shared/data/photometry}/ies/lm63_2002_lithonia_area_full_h0_360.ies}
n=${3:-65536}
bin=$(mktemp /tmp/soa_batch.XXXXXX)
cc -O2 -Wall -Wextra -Werror -I crates/gonio-capi/include benches/c/soa_batch.c "$lib" -lpthread -ldl -lm -o "$bin"
for f in gonio_sample_batch_soa gonio_pdf_batch_soa gonio_invert_batch_soa \
  gonio_sample_batch_soa_f32 gonio_pdf_batch_soa_f32 gonio_invert_batch_soa_f32; do
  ir=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null --toggle-collect="$f" "$bin" "$file" \
    "$n" 1 2>&1 >/dev/null | awk '/Collected :/ { print $NF }')
  awk -v f="$f" -v ir="$ir" -v n="$n" 'BEGIN { printf "%-28s %8.1f instructions per point\n", f, ir / n }'
done
rm -f "$bin"
