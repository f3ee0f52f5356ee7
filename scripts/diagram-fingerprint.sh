#!/bin/sh
# Prints one hash per built-in model and shipped model file over everything `hybridcont run` writes
# (CSV files and summary.json without the report's wall time and work counts and the folder's status), for checking that a change
# of the code leaves every diagram equal to the bit.
#   sh scripts/diagram-fingerprint.sh [BUILD_DIR] [extra run options...]
# Compare the output before and after a change: equal lines mean equal diagrams.
set -eu
build=${1:-build}
[ $# -gt 0 ] && shift
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
models="slip bouncing-ball rocking-block bouncing-rod ball-chain"
for f in "$root"/models/*.toml; do models="$models $f"; done
for m in $models; do
  case "$m" in *.toml) name="file:$(basename "$m" .toml)" ;; *) name="$m" ;; esac
  out="$work/$name"
  "$build/hybridcont" run "$m" --no-plots --quiet --out "$out" "$@" >/dev/null 2>&1 || echo "$name: run failed ($?)"
  # Left out: the wall time and work counts (they vary with threads) and the folder's status line.
  sed -i -e 's/wall time [^\\]*/(wall time and work counts left out: they vary with threads)/' -e '/^ "status": "complete",$/d' "$out/summary.json"
  hash=$(cd "$out" && cat $(ls | sort) | sha256sum | cut -c1-16)
  echo "$name $hash $(ls "$out" | wc -l) files"
done
