#!/usr/bin/python3
"""The table of docs/shipped-examples.md: every model under models/ run from its shipped start, and per family
(its [[families]] name, with the word of an automaton) where its orbits are physical and where stable, from
summary.json's physical_ranges and stable_ranges. Each stretch is written low-high in the continued coordinate,
an end at a located special point with its code ([TP #4]).

    scripts/shipped-examples-table.py build/hybridcont /tmp/shipped > table.md

Runs the models one after the other (the bipedal ones take a minute); a model whose run fails is listed with
its exit code.
"""
import argparse
import json
import os
import re
import subprocess
import sys

MODELS = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "models")
SHOWN = 3  # stretches shown per cell; more are counted


def end(value, how):
    code = re.match(r"([A-Z]{2} #\d+), located", how)
    return f"{value:g}" + (f"[{code.group(1)}]" if code else "")


def stretches(ranges):
    cells = []
    for r in sorted(ranges, key=lambda r: min(r["from"], r["to"])):
        ends = sorted([(r["from"], r["from_how"]), (r["to"], r["to_how"])])
        cells.append(f"{end(*ends[0])}–{end(*ends[1])}")
    if not cells:
        return "—"
    more = f", … ({len(cells)} stretches)" if len(cells) > SHOWN else ""
    return ", ".join(cells[:SHOWN]) + more


def rows(name, summary):
    """One row per family: each stretch counts for the family named in it (a branch may cross from one family
    into another at a fold); with the word of its branch where the run explored several words."""
    coordinate = re.search(r"where stable, in ([^)]+)\)", summary["report"])
    coordinate = coordinate.group(1) if coordinate else "?"
    words = {tuple(b.get("word", [])) for b in summary["branches"]}
    families = {}
    for b in summary["branches"]:
        word = f" ({' > '.join(b['word'])})" if len(words) > 1 else ""
        for kind in ("physical_ranges", "stable_ranges"):
            for r in b.get(kind, []):
                physical, stable = families.setdefault(r["family"] + word, ([], []))
                (physical if kind == "physical_ranges" else stable).append(r)
    for label, (physical, stable) in families.items():
        yield f"| {name} | {label} | {coordinate}: {stretches(physical)} | {stretches(stable)} |"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("binary", help="the hybridcont executable")
    parser.add_argument("out", help="a folder for the runs' results (one subfolder per model)")
    args = parser.parse_args()
    print("| model | family | physical (branch stretches) | stable |")
    print("|---|---|---|---|")
    for file in sorted(os.listdir(MODELS)):
        if not file.endswith(".toml"):
            continue
        name = file[:-len(".toml")]
        out = os.path.join(args.out, name)
        run = subprocess.run([args.binary, "run", os.path.join(MODELS, file), "--out", out, "--quiet", "--no-plots",
                              "--overwrite"], capture_output=True, text=True)
        if run.returncode != 0:
            print(f"| {name} | (run failed: exit {run.returncode}) | | |")
            print(run.stderr, file=sys.stderr)
            continue
        with open(os.path.join(out, "summary.json")) as f:
            for row in rows(name, json.load(f)):
                print(row)


if __name__ == "__main__":
    main()
