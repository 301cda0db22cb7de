#!/usr/bin/env bash
# The README's test command: every test of the project — the Rust workspace, the Python package
# and the C/C++ examples — in one run. Each part is a script of its own under scripts/ so that it can
# also be run alone; a part that cannot run on this machine says so in the summary at the end.
set -euo pipefail
cd "$(dirname "$0")/.."

status=0
summary=()
run_part() {
  local name="$1"; shift
  echo
  echo "==== ${name}: $*"
  local rc=0 t0=$SECONDS
  "$@" || rc=$?
  local took="$((SECONDS - t0)) s"
  case "$rc" in
    0) summary+=("${name}: ok (${took})") ;;
    # 77: the part cannot run on this machine (it printed why); not a failure.
    77) summary+=("${name}: SKIPPED (see its output; ${took})") ;;
    *) summary+=("${name}: FAILED (${took})")
       status=1 ;;
  esac
}

# The Rust tests: unit, integration and doc tests. The examples are not built here (`cargo test`
# alone would build all of them, about a minute and a half on 2 cores, to run nothing):
# `.ci/run`'s `cargo clippy --all-targets` compiles them.
rust_tests() {
  cargo test --workspace --locked --lib --bins --tests && cargo test --workspace --locked --doc
}
run_part "rust" rust_tests
for part in python c; do
  if [ -f "scripts/test-${part}.sh" ]; then
    run_part "${part}" bash "scripts/test-${part}.sh"
  fi
done

echo
echo "==== summary"
printf '%s\n' "${summary[@]}"
exit "$status"
