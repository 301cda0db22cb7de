#!/usr/bin/env bash
# Dumps `gonio sample/pdf/invert/info` for every corpus file and `example` into a folder, so two
# builds can be compared byte for byte (issue 24's invariant), with `gonio tables` in both precisions:
#   scripts/dump-outputs.sh target/debug/gonio /tmp/before
#   (change, rebuild)
#   scripts/dump-outputs.sh target/debug/gonio /tmp/after && diff -r /tmp/before /tmp/after
# With the environment maps of the folder beside the corpus (or the 4th argument).
# `info`'s build-time line is masked (a wall-clock time differs run to run).
set -u
bin=${1:?usage: dump-outputs.sh GONIO_BINARY OUT_DIR [CORPUS_DIR [ENVMAP_DIR]]}
out=${2:?usage: dump-outputs.sh GONIO_BINARY OUT_DIR [CORPUS_DIR [ENVMAP_DIR]]}
corpus=${3:-/work/shared/data/photometry}
envmaps=${4:-$(dirname "$corpus")/envmaps}
mkdir -p "$out"
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
corpus=$(cd "$corpus" && pwd)
envmaps=$(cd "$envmaps" 2>/dev/null && pwd)
cd "$out" || exit 1
out=.
# Relative, so that warnings naming it are the same whatever OUT_DIR is.
dirs=dirs.csv
{
  echo "x,y,z"
  for t in 0 15 45 89.5 90 90.5 135 179 180; do
    for p in 0 37 90 200 359; do
      awk -v t="$t" -v p="$p" 'BEGIN { d = atan2(0, -1) / 180; printf "%.17g,%.17g,%.17g\n", sin(t*d)*cos(p*d), sin(t*d)*sin(p*d), cos(t*d) }'
    done
  done
} >"$dirs"
# The map's tables in both precisions (docs/TABLES.md): the float32 blob holds every table the
# float32 map reads, so equal blobs mean an equal float32 map.
tables() {
  for p in f32 f64; do
    "$bin" tables "$1" -o "$out/$2.$p.tables" --precision "$p" 2>"$out/$2.$p.tables.err"; echo "rc=$?" >>"$out/$2.$p.tables.err"
  done
}
inputs=(example)
while IFS= read -r f; do inputs+=("$f"); done < <(find "$corpus" -type f \( -iname '*.ies' -o -iname '*.ldt' -o -iname '*.json' \) | sort)
for f in "${inputs[@]}"; do
  tag=$(basename "$f" | sed 's/[^A-Za-z0-9._-]/_/g')
  for m in hds piecewise-constant; do
    "$bin" sample "$f" -n 200 --method "$m" >"$out/$tag.$m.sample" 2>"$out/$tag.$m.sample.err"; echo "rc=$?" >>"$out/$tag.$m.sample.err"
    "$bin" pdf "$f" --directions "$dirs" --method "$m" >"$out/$tag.$m.pdf" 2>"$out/$tag.$m.pdf.err"; echo "rc=$?" >>"$out/$tag.$m.pdf.err"
    "$bin" invert "$f" --directions "$dirs" --method "$m" >"$out/$tag.$m.invert" 2>"$out/$tag.$m.invert.err"; echo "rc=$?" >>"$out/$tag.$m.invert.err"
  done
  "$bin" info "$f" 2>&1 | sed -E 's/[0-9.]+ ?(ms|µs|s)\b/T\1/g' >"$out/$tag.info"; echo "rc=${PIPESTATUS[0]}" >>"$out/$tag.info"
  tables "$f" "$tag"
done
# The environment maps beside the corpus (../shared/data/envmaps): the HDS sphere map of each.
for f in ${envmaps:+"$envmaps"/*.hdr}; do
  tag=env.$(basename "$f")
  "$bin" sample "$f" -n 2000 >"$out/$tag.sample" 2>"$out/$tag.sample.err"; echo "rc=$?" >>"$out/$tag.sample.err"
  "$bin" pdf "$f" --directions "$dirs" >"$out/$tag.pdf" 2>"$out/$tag.pdf.err"; echo "rc=$?" >>"$out/$tag.pdf.err"
  "$bin" invert "$f" --directions "$dirs" >"$out/$tag.invert" 2>"$out/$tag.invert.err"; echo "rc=$?" >>"$out/$tag.invert.err"
  "$bin" info "$f" 2>&1 | sed -E 's/[0-9.]+ ?(ms|µs|s)\b/T\1/g' >"$out/$tag.info"; echo "rc=${PIPESTATUS[0]}" >>"$out/$tag.info"
  tables "$f" "$tag"
done
echo "$(ls | wc -l) files in $(pwd)"
