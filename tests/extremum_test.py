"""Extrema of an observable along a family (EX points), and their curve in a second parameter.

The bipedal spring-mass model's walking gait (models/bipedal-slip.toml) needs the smallest peak leg force in
single stance at H = 1.0270 (`--extremum peak_force`). Checked three ways:

1. The answer and summary.json name it: a minimum of peak_force on the walking family, located.
2. An independent location of the same minimum: the two points where peak_force crosses a value just above the
   minimum (`--monitor`, UZ points, located from the observable's values rather than from the tangent) lie on
   either side of it, their midpoint within the cubic term's offset of its H (for a value delta above the
   minimum m with curvature a the crossings are sqrt(delta / a) away, and the cubic term moves their midpoint by
   about (m''' / (3 m'')) delta / a: ~1e-8 here), and no sampled point of the branch between them lies below it.
3. Its curve in (H, k) (`--curves k`): at a point of the curve away from the model's k, a run at that k locates
   the walking family's smallest peak force at the curve's H, within the precision it states.

Environment: HYBRIDCONT_BIN (the hybridcont executable), HYBRIDCONT_MODELS (the shipped model files).
"""
import csv
import json
import os
import subprocess

import pytest

BIN = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
MODEL = os.path.join(os.environ.get("HYBRIDCONT_MODELS", "models"), "bipedal-slip.toml")


def run(out, *args):
    done = subprocess.run([BIN, "run", MODEL, *args, "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr + done.stdout
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f), done.stdout


def walking_minimum(summary, near=1.027):
    """The minimum of peak_force on the walking family nearest H = near (the one the answer lists)."""
    walking = {b["id"] for b in summary["branches"] if b.get("family") == "walking"}
    found = [p for p in summary["special_points"]
             if p["type"] == "EX" and p["component"] == "peak_force" and p["branch"] in walking
             and p["duplicate_of"] < 0 and p.get("extremum") == "minimum" and abs(p["H"] - near) < 0.01]
    assert found
    return min(found, key=lambda p: abs(p["H"] - near))


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("bipedal_ex")
    summary, answer = run(out, "--extremum", "peak_force", "--curves", "k", "--bound", "k=24:27", "--quiet")
    return out, summary, answer


def test_the_smallest_peak_force_of_walking_is_located_and_said(study):
    _, summary, answer = study
    ex = walking_minimum(summary)
    assert ex["extremum"] == "minimum" and ex["status"] == "located"
    assert ex["H"] == pytest.approx(1.0270007, abs=1e-6)
    assert ex["peak_force"] == pytest.approx(1.0998579, abs=1e-6)
    assert "extrema along the families:\n  walking: smallest peak_force 1.099857883 at H = 1.027000685 (%s)" % (
        ex["label"]) in answer


def test_monitored_crossings_just_above_the_minimum_bracket_it(study, tmp_path):
    out, summary, _ = study
    ex = walking_minimum(summary)
    delta = 1e-8
    crossing, _ = run(tmp_path, "--monitor", "peak_force=%.17g" % (ex["peak_force"] + delta), "--quiet")
    near = sorted(p["H"] for p in crossing["special_points"]
                  if p["type"] == "UZ" and p["status"] == "located" and abs(p["H"] - ex["H"]) < 1e-3)
    assert len(near) == 2, near
    assert near[0] < ex["H"] < near[1]
    assert (near[0] + near[1]) / 2 == pytest.approx(ex["H"], abs=1e-7)
    # The branch's own samples between them (if any) are not below the minimum.
    branch = next(b for b in summary["branches"] if b["id"] == ex["branch"])
    with open(os.path.join(out, branch["file"]), newline="") as f:
        for row in csv.DictReader(f):
            if near[0] <= float(row["H"]) <= near[1]:
                assert float(row["peak_force"]) >= ex["peak_force"] - 1e-12


def test_the_curve_of_the_minimum_in_k_meets_a_run_at_another_k(study, tmp_path):
    out, summary, _ = study
    ex = walking_minimum(summary)
    curve = next(c for c in summary["curves"] if c["type"] == "extremum" and c["special_point"] == ex["id"])
    assert curve["status"] == "traced" and curve["coordinate"] == "H"
    with open(os.path.join(out, curve["file"]), newline="") as f:
        rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    assert list(rows[0])[:2] == ["H", "k"] and "peak_force" in rows[0]
    at = min(rows, key=lambda r: abs(r["k"] - 26.5))
    assert abs(at["k"] - 25.484) > 0.5  # away from the run's own k
    there, _ = run(tmp_path, "--set", "k=%.17g" % at["k"], "--extremum", "peak_force", "--quiet")
    other = walking_minimum(there, near=at["H"])
    assert abs(other["H"] - at["H"]) <= max(other["precision"], 1e-12), (other["H"], at["H"], other["precision"])
    assert other["peak_force"] == pytest.approx(at["peak_force"], abs=1e-8)
