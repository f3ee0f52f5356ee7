#!/bin/sh
# Runs every built-in model and shipped model file with two builds of the tool and compares their results
# folders: every CSV file byte for byte (where they differ, the columns and the largest relative difference), summary.json as JSON without the report's wall time and work counts
# and without keys only the second build writes (a grown format: those are named, not counted as
# differences). For checking that a change leaves every diagram equal when the folder's format grows (the
# hashes of scripts/diagram-fingerprint.sh then change through the new keys alone).
#   sh scripts/compare-builds.sh OLD_BUILD_DIR NEW_BUILD_DIR [extra run options...]
set -eu
old=$1
new=$2
shift 2
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
models="slip bouncing-ball rocking-block bouncing-rod ball-chain"
for f in "$root"/models/*.toml; do models="$models $f"; done
for m in $models; do
  case "$m" in *.toml) name="file-$(basename "$m" .toml)" ;; *) name="$m" ;; esac
  "$old/hybridcont" run "$m" --no-plots --quiet --threads 1 --out "$work/old/$name" "$@" >/dev/null 2>&1 || echo "$name: old build failed"
  "$new/hybridcont" run "$m" --no-plots --quiet --threads 1 --out "$work/new/$name" "$@" >/dev/null 2>&1 || echo "$name: new build failed"
  python3 - "$work/old/$name" "$work/new/$name" "$name" <<'PY'
import csv, json, os, re, sys
a, b, name = sys.argv[1:4]
fa, fb = sorted(os.listdir(a)), sorted(os.listdir(b))
out, grown = [], set()
columns, differing = {}, []
if fa != fb:
    out.append('files differ: %s' % sorted(set(fa) ^ set(fb)))
def strip_new(x, y, path):
    # keys y has and x lacks, recursively through objects and lists of equal length
    if isinstance(x, dict) and isinstance(y, dict):
        for k in list(y):
            if k not in x:
                grown.add(re.sub(r'\[\d+\]', '[]', path + '.' + k)); del y[k]
            else:
                strip_new(x[k], y[k], path + '.' + k)
    elif isinstance(x, list) and isinstance(y, list) and len(x) == len(y):
        for i, (p, q) in enumerate(zip(x, y)):
            strip_new(p, q, '%s[%d]' % (path, i))
for f in fa:
    if f not in fb or f == 'report.html':  # the report is drawn from the study: compared through summary.json
        continue
    if f == 'summary.json':
        x, y = json.load(open(os.path.join(a, f))), json.load(open(os.path.join(b, f)))
        strip_new(x, y, 'summary')
        for j in (x, y):
            j['report'] = re.sub(r'wall time .*', '', j.get('report', ''), flags=re.S)
        if x != y:
            out.append('summary.json differs in %s' % sorted(k for k in set(x) | set(y) if x.get(k) != y.get(k)))
    elif open(os.path.join(a, f), 'rb').read() != open(os.path.join(b, f), 'rb').read():
        # Which columns, by how much: the largest difference relative to 1 + |value| per column.
        ra, rb = list(csv.reader(open(os.path.join(a, f)))), list(csv.reader(open(os.path.join(b, f))))
        if len(ra) != len(rb) or ra[:1] != rb[:1]:
            out.append(f + ' differs in rows or header')
            continue
        worst = {}
        for x, y in zip(ra[1:], rb[1:]):
            for c, (p, q) in enumerate(zip(x, y)):
                if p == q:
                    continue
                try:
                    d = abs(float(p) - float(q)) / (1 + abs(float(q)))
                except ValueError:
                    d = float('inf')
                worst[ra[0][c]] = max(worst.get(ra[0][c], 0), d)
        for column, d in worst.items():
            columns[column] = max(columns.get(column, 0), d)
        differing.append(f)
if differing:
    out.append('%d CSV files differ, by column (largest |a - b| / (1 + |b|)): %s' % (
        len(differing), ', '.join('%s %.1e' % kv for kv in sorted(columns.items(), key=lambda kv: -kv[1]))))
print('%s: %s%s' % (name, '; '.join(out) if out else 'equal',
                     (' (new keys: %s)' % ', '.join(sorted(grown))) if grown else ''))
PY
done
