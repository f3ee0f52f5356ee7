#!/bin/sh
# Runs every built-in model and shipped model file with two builds of the tool and compares their results
# folders: every CSV file byte for byte, summary.json as JSON without the report's wall time and work counts
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
import json, os, re, sys
a, b, name = sys.argv[1:4]
fa, fb = sorted(os.listdir(a)), sorted(os.listdir(b))
out, grown = [], set()
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
    if f not in fb:
        continue
    if f == 'summary.json':
        x, y = json.load(open(os.path.join(a, f))), json.load(open(os.path.join(b, f)))
        strip_new(x, y, 'summary')
        for j in (x, y):
            j['report'] = re.sub(r'wall time .*', '', j.get('report', ''), flags=re.S)
        if x != y:
            out.append('summary.json differs in %s' % sorted(k for k in set(x) | set(y) if x.get(k) != y.get(k)))
    elif open(os.path.join(a, f), 'rb').read() != open(os.path.join(b, f), 'rb').read():
        out.append(f + ' differs')
print('%s: %s%s' % (name, '; '.join(out) if out else 'equal',
                     (' (new keys: %s)' % ', '.join(sorted(grown))) if grown else ''))
PY
done
