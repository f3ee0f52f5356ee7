#!/usr/bin/env bash
# Fuzzes the model-file reader (a model file is untrusted input; docs/model-files.md):
#   1. the standalone driver (tests/fuzz/fuzz_driver.cc, any compiler) on N generated inputs, in chunks,
#      resuming after a crash or a hang at the next input;
#   2. libFuzzer under AddressSanitizer + UndefinedBehaviorSanitizer (clang), from the seed corpus
#      models/*.toml + tests/fuzz/corpus/*.toml with the dictionary tests/fuzz/model_file.dict, for a time or
#      a number of runs.
# Findings (inputs that crash, hang > 1 s, throw anything but std::invalid_argument, or are refused without
# file:line) are saved under the work folder; the summary at the end says where.
#
#   scripts/fuzz-model-files.sh                          # 1e5 driver inputs, then libFuzzer for 300 s
#   scripts/fuzz-model-files.sh --time 60 --driver-inputs 3000
#   scripts/fuzz-model-files.sh --runs 200000 --skip-driver
#   scripts/fuzz-model-files.sh --replay crash-1234      # one saved input through both binaries
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DRIVER_BUILD="$ROOT/build"
LIBFUZZER_BUILD="$ROOT/build-libfuzzer"
WORK="$ROOT/build-libfuzzer/fuzz-work"
CLANG="${CLANG:-clang++-14}"
DRIVER_INPUTS=100000
CHUNK=20000
SEED=1
TIME=300
RUNS=""
TIMEOUT=1         # seconds per input before libFuzzer calls it a hang (the driver's --time-limit too)
JOBS=2
STRICT=0          # 1: libFuzzer also stops at a broken contract (a refusal without file:line, ...)
SKIP_DRIVER=0
SKIP_LIBFUZZER=0
REPLAY=()

usage() {
  sed -n '2,16p' "$0" | sed 's/^# \{0,1\}//'
  cat <<EOF
options:
  --driver-inputs N     inputs through the standalone driver (default $DRIVER_INPUTS)
  --seed S              the driver's seed (default $SEED)
  --time SECONDS        libFuzzer's run time (default $TIME)
  --runs N              libFuzzer's number of runs instead of a time
  --timeout SECONDS     per-input limit, both fuzzers (default $TIMEOUT)
  --strict              libFuzzer stops at a broken contract too (HYBRIDCONT_FUZZ_STRICT=1)
  --driver-build DIR    build folder of the driver (default $DRIVER_BUILD; configured if needed)
  --libfuzzer-build DIR clang + sanitizers build folder (default $LIBFUZZER_BUILD)
  --work DIR            corpus, findings and logs (default $WORK)
  --jobs N              build jobs (default $JOBS)
  --skip-driver, --skip-libfuzzer
  --replay FILE...      run saved inputs through both binaries and stop
EOF
  exit "${1:-0}"
}

while [[ $# -gt 0 ]]; do
  case "$1" in
    --driver-inputs) DRIVER_INPUTS="$2"; shift 2 ;;
    --seed) SEED="$2"; shift 2 ;;
    --time) TIME="$2"; RUNS=""; shift 2 ;;
    --runs) RUNS="$2"; shift 2 ;;
    --timeout) TIMEOUT="$2"; shift 2 ;;
    --strict) STRICT=1; shift ;;
    --driver-build) DRIVER_BUILD="$(realpath -m "$2")"; shift 2 ;;
    --libfuzzer-build) LIBFUZZER_BUILD="$(realpath -m "$2")"; WORK="$LIBFUZZER_BUILD/fuzz-work"; shift 2 ;;
    --work) WORK="$(realpath -m "$2")"; shift 2 ;;
    --jobs) JOBS="$2"; shift 2 ;;
    --skip-driver) SKIP_DRIVER=1; shift ;;
    --skip-libfuzzer) SKIP_LIBFUZZER=1; shift ;;
    --replay) shift; while [[ $# -gt 0 && "$1" != --* ]]; do REPLAY+=("$(realpath "$1")"); shift; done ;;
    -h|--help) usage 0 ;;
    *) echo "error: unknown argument '$1'" >&2; usage 2 >&2 ;;
  esac
done

mkdir -p "$WORK"
DRIVER="$DRIVER_BUILD/tests/fuzz/model_file_fuzz_driver"
LIBFUZZER="$LIBFUZZER_BUILD/tests/fuzz/model_file_libfuzzer"
export ASAN_OPTIONS="${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:detect_stack_use_after_return=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"

build_driver() {
  if [[ ! -f "$DRIVER_BUILD/CMakeCache.txt" ]]; then
    cmake -S "$ROOT" -B "$DRIVER_BUILD" -DCMAKE_BUILD_TYPE=Release -DHYBRIDCONT_BUILD_BENCH=OFF >/dev/null
  fi
  cmake --build "$DRIVER_BUILD" --target model_file_fuzz_driver -j"$JOBS"
}

build_libfuzzer() {
  if ! command -v "$CLANG" >/dev/null; then
    echo "error: $CLANG not found (Debian: apt-get install clang-14 libclang-rt-14-dev; or set CLANG=...)" >&2
    exit 2
  fi
  # Every library instrumented for coverage and both sanitizers; only the fuzzer binary links libFuzzer.
  cmake -S "$ROOT" -B "$LIBFUZZER_BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER="$CLANG" \
    -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined -fno-omit-frame-pointer" \
    -DHYBRIDCONT_LIBFUZZER=ON -DHYBRIDCONT_BUILD_BENCH=OFF >/dev/null
  cmake --build "$LIBFUZZER_BUILD" --target model_file_libfuzzer -j"$JOBS"
}

if [[ ${#REPLAY[@]} -gt 0 ]]; then
  [[ $SKIP_DRIVER == 1 ]] || { build_driver; "$DRIVER" --work "$WORK/replay" --replay "${REPLAY[@]}" || true; }
  [[ $SKIP_LIBFUZZER == 1 ]] || { build_libfuzzer; HYBRIDCONT_FUZZ_STRICT=$STRICT "$LIBFUZZER" "${REPLAY[@]}"; }
  exit 0
fi

status=0
summary=()

# ---- 1. the standalone driver, in chunks; a crash or hang ends a chunk, the next input starts the next.
if [[ $SKIP_DRIVER == 0 ]]; then
  build_driver
  mkdir -p "$WORK/driver"
  tried=0 parsed=0 rejected=0 late=0 findings=0 crashes=0
  start=0
  t0=$(date +%s)
  while (( start < DRIVER_INPUTS )); do
    n=$(( DRIVER_INPUTS - start < CHUNK ? DRIVER_INPUTS - start : CHUNK ))
    log="$WORK/driver/chunk-$SEED-$start.log"
    rc=0
    "$DRIVER" --seed "$SEED" --start "$start" --inputs "$n" --time-limit "$TIMEOUT" --work "$WORK/driver" \
      >"$log" 2>&1 || rc=$?
    if (( rc == 0 || rc == 1 )); then
      count() { sed -n "s/^$1.*: *\([0-9][0-9]*\)\$/\1/p" "$log"; }
      tried=$(( tried + $(sed -n 's/^model-file fuzzing: \([0-9][0-9]*\) inputs tried.*/\1/p' "$log") ))
      parsed=$(( parsed + $(count '  parsed OK') ))
      rejected=$(( rejected + $(count '  rejected with ModelInputError') ))
      late=$(( late + $(count '  accepted, refused at run set-up') ))
      findings=$(( findings + $(sed -n 's/^  findings: \([0-9][0-9]*\).*/\1/p' "$log") ))
      grep -E '^(FINDING|NOTE)' "$log" || true
      start=$(( start + n ))
    else
      # Died at an input: the driver named it; count the inputs before it as tried, resume after it.
      at=$(grep -o 'at input s[0-9]*-[0-9]*' "$log" | tail -1 | sed 's/.*-//')
      grep -E 'CRASH|HANG|FINDING' "$log" || true
      if [[ -z "$at" ]]; then echo "error: the driver died (exit $rc) without naming an input; see $log" >&2; exit 1; fi
      echo "driver: input $at of seed $SEED ended the process (exit $rc); resuming at $(( at + 1 ))"
      tried=$(( tried + at - start + 1 ))
      findings=$(( findings + 1 )) crashes=$(( crashes + 1 ))
      start=$(( at + 1 ))
    fi
    echo "driver: $start / $DRIVER_INPUTS inputs ($(( $(date +%s) - t0 )) s)"
  done
  seconds=$(( $(date +%s) - t0 ))
  summary+=("driver: $tried inputs in $seconds s (seed $SEED): parsed OK $parsed, rejected with ModelInputError $rejected, accepted but refused at run set-up $late, findings $findings (process deaths $crashes); logs and saved inputs in $WORK/driver")
  (( findings == 0 )) || status=1
fi

# ---- 2. libFuzzer under ASan + UBSan.
if [[ $SKIP_LIBFUZZER == 0 ]]; then
  build_libfuzzer
  corpus="$WORK/corpus"
  mkdir -p "$corpus" "$WORK/artifacts"
  cp "$ROOT"/models/*.toml "$ROOT"/tests/fuzz/corpus/*.toml "$corpus"/
  limit=(-max_total_time="$TIME")
  [[ -z "$RUNS" ]] || limit=(-runs="$RUNS")
  log="$WORK/libfuzzer.log"
  t0=$(date +%s)
  rc=0
  HYBRIDCONT_FUZZ_STRICT=$STRICT "$LIBFUZZER" "$corpus" "${limit[@]}" -timeout="$TIMEOUT" -max_len=16384 \
    -rss_limit_mb=2048 -dict="$ROOT/tests/fuzz/model_file.dict" -artifact_prefix="$WORK/artifacts/" \
    -print_final_stats=1 2>&1 | tee "$log" | grep -E '^#[0-9]+.*(pulse|DONE)|ERROR|SUMMARY|Test unit|artifact' || true
  rc=${PIPESTATUS[0]}
  seconds=$(( $(date +%s) - t0 ))
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1)
  if (( rc == 0 )); then
    summary+=("libFuzzer (ASan+UBSan): ${runs:-?} runs in $seconds s, ${cov:-cov ?}, no finding; corpus $corpus")
  else
    status=1
    summary+=("libFuzzer (ASan+UBSan): FINDING after ${runs:-?} runs in $seconds s (exit $rc); see $log and $WORK/artifacts/")
  fi
fi

echo
printf '%s\n' "${summary[@]}"
exit $status
