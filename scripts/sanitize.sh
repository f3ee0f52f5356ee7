#!/bin/sh
# The test suite under the sanitizers, each in a build folder of its own:
#   sh scripts/sanitize.sh asan   AddressSanitizer + UndefinedBehaviorSanitizer (+ LeakSanitizer), every test
#   sh scripts/sanitize.sh tsan   ThreadSanitizer, every test (the concurrent exploration above all)
#   sh scripts/sanitize.sh        both
# A finding aborts the test that made it (halt_on_error), so a green run means zero findings. The
# package test is left out: it builds a consumer against the installed, uninstrumented way of linking.
# Installs what is missing first (scripts/install-deps.sh). Durations are in bench/README.md.
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
sh "$root/scripts/install-deps.sh"
jobs=${JOBS:-2}
run() {  # run NAME SANITIZERS
  name=$1
  dir="$root/build-$name"
  start=$(date +%s)
  cmake -S "$root" -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHYBRIDCONT_SANITIZE="$2" \
        -DHYBRIDCONT_BUILD_BENCH=OFF >/dev/null
  cmake --build "$dir" -j"$jobs"
  built=$(date +%s)
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
    ctest --test-dir "$dir" --output-on-failure -j"$jobs" -LE package --timeout 1200
  echo "sanitize $name ($2): build $((built - start)) s, tests $(($(date +%s) - built)) s, no findings"
}
case "${1:-all}" in
  asan) run asan address,undefined ;;
  tsan) run tsan thread ;;
  all) run asan address,undefined; run tsan thread ;;
  *) echo "usage: sh scripts/sanitize.sh [asan|tsan|all]" >&2; exit 2 ;;
esac
