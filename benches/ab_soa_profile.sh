#!/usr/bin/env bash
# A/B timing of two builds of the `soa_profile` example on a noisy machine: runs them alternately,
# ROUNDS processes each (default 5), each the best of REP repeats (default 20) over 2^16 Halton
# points of the side-by-side script's grid, and prints the best of each build in ns per point.
#
#   cargo build --release -p gonio --example soa_profile && cp target/release/examples/soa_profile /tmp/A
#   (change the code) ... && cp target/release/examples/soa_profile /tmp/B
#   benches/ab_soa_profile.sh /tmp/A /tmp/B soa-invert-f64 19 36 [ROUNDS]
set -euo pipefail
if [ $# -lt 5 ]; then
  echo "usage: $0 BINARY_A BINARY_B OP N M [ROUNDS]" >&2
  exit 2
fi
a=$1; b=$2; op=$3; n=$4; m=$5; rounds=${6:-5}
for _ in $(seq "$rounds"); do
  for x in A B; do
    bin=$a; [ "$x" = B ] && bin=$b
    t=$(GONIO_PROFILE_FAMILY=peaky GONIO_PROFILE_REPEAT="${REP:-20}" "$bin" "$op" "$n" "$m" 2>&1 \
      | grep -o '[0-9.]* ns per point' | cut -d' ' -f1)
    echo "$x $t"
  done
done | sort -k1,1 -k2n | awk '!seen[$1]++ { printf "%s %s ns  ", $1, $2 } END { print "" }' \
  | sed "s/^/$op $n x $m: /"
