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
# ASan + UBSan is built with clang: GCC 12 spends over 25 minutes on each file that instantiates the
# automatic differentiation under -fsanitize=address,undefined (expression_model.cc: clang 14 46 s).
if ! command -v clang++ >/dev/null 2>&1 || ! dpkg -s libclang-rt-14-dev >/dev/null 2>&1; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq clang libclang-rt-14-dev >/dev/null
fi
jobs=${JOBS:-2}
run() {  # run NAME SANITIZERS COMPILER OPTIMIZATION
  name=$1
  dir="$root/build-$name"
  start=$(date +%s)
  cmake -S "$root" -B "$dir" -DCMAKE_CXX_COMPILER="$3" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$4 -g" -DHYBRIDCONT_SANITIZE="$2" -DHYBRIDCONT_BUILD_BENCH=OFF >/dev/null
  cmake --build "$dir" -j"$jobs"
  built=$(date +%s)
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
    ctest --test-dir "$dir" --output-on-failure -j"$jobs" -LE package --timeout 1200
  echo "sanitize $name ($2): build $((built - start)) s, tests $(($(date +%s) - built)) s, no findings"
}
case "${1:-all}" in
  asan) run asan address,undefined clang++ -O1 ;;
  tsan) run tsan thread g++ -O2 ;;
  all) run asan address,undefined clang++ -O1; run tsan thread g++ -O2 ;;
  *) echo "usage: sh scripts/sanitize.sh [asan|tsan|all]" >&2; exit 2 ;;
esac
