"""Special points continued in two parameters where the families are not followed in H.

1. At a fixed energy (`--free k --fix H=1.5 --curves w2`): the SLIP's branch point where forward hopping leaves
   hopping in place, and the period doubling of forward hopping, continued in (k, w2) at H = 1.5. At points of
   each curve far from the run's w2, a one-parameter study at that w2 (families in k at H = 1.5) locates its SB
   and PD at the curve's k, within the precision it states for them.
2. Without a first integral (the forced impact oscillator, families in the forcing frequency w, `--curves A`):
   its grazing points continued in (w, A) agree with the closed form of the non-impacting response touching
   the stop, A = d sqrt((k - w^2)^2 + (c w)^2), along the whole curve, with the curve's lowest amplitude
   (its turning point in A) at w^2 = k - c^2/2; the second grazing point lies on the first one's curve and is
   not traced again; the period-doubling curve passes through the PD of a run at another amplitude.

Environment: HYBRIDCONT_BIN (the hybridcont executable), HYBRIDCONT_MODELS (the shipped model files).
"""
import csv
import json
import math
import os
import subprocess

import pytest

BIN = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
MODELS = os.environ.get("HYBRIDCONT_MODELS", "models")


def run(out, *args):
    done = subprocess.run([BIN, "run", *args, "--out", str(out), "--quiet"], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr + done.stdout
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


def curve_rows(out, curve):
    with open(os.path.join(out, curve["file"]), newline="") as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def nearest(rows, column, value):
    return min(rows, key=lambda r: abs(r[column] - value))


@pytest.fixture(scope="module")
def slip_plane(tmp_path_factory):
    out = tmp_path_factory.mktemp("slip_k_w2")
    return out, run(out, "slip", "--set", "w2=6", "--free", "k", "--fix", "H=1.5", "--curves", "w2")


def test_slip_curves_at_fixed_energy_are_in_k_and_w2(slip_plane):
    out, summary = slip_plane
    curves = summary["curves"]
    assert sorted(c["type"] for c in curves) == ["branch-point", "period-doubling"]
    labels = {sp["id"]: sp["label"] for sp in summary["special_points"]}
    assert {labels[c["special_point"]] for c in curves} == {"SB0", "PD2"}
    for c in curves:
        assert c["coordinate"] == "k" and c["status"] == "traced"
        rows = curve_rows(out, c)
        assert list(rows[0])[:2] == ["k", "w2"]
        assert all(abs(r["H"] - 1.5) < 1e-12 for r in rows)  # the energy stays fixed along the curve
    assert "from special point 3 (PD): on curve" in summary["report"]  # PD3, the mirror image, not traced again


@pytest.mark.parametrize("kind,code,w2", [("branch-point", "SB", 4.5), ("branch-point", "SB", 7.0),
                                          ("period-doubling", "PD", 9.0), ("period-doubling", "PD", 16.0)])
def test_slip_curve_points_are_where_one_parameter_runs_locate_them(slip_plane, tmp_path, kind, code, w2):
    out, summary = slip_plane
    curve = next(c for c in summary["curves"] if c["type"] == kind)
    at = nearest(curve_rows(out, curve), "w2", w2)
    there = run(tmp_path, "slip", "--set", "w2=%.17g" % at["w2"], "--free", "k", "--fix", "H=1.5")
    found = [sp for sp in there["special_points"] if sp["type"] == code and sp["status"] == "located"]
    assert found, "no %s at w2 = %.17g" % (code, at["w2"])
    best = min(found, key=lambda sp: abs(sp["k"] - at["k"]))
    assert abs(best["k"] - at["k"]) <= best["precision"], (best["k"], at["k"], best["precision"])


@pytest.fixture(scope="module")
def oscillator_plane(tmp_path_factory):
    out = tmp_path_factory.mktemp("oscillator_w_A")
    model = os.path.join(MODELS, "forced-impact-oscillator.toml")
    return out, model, run(out, model, "--curves", "A")


def test_grazing_curve_of_the_impact_oscillator_is_the_closed_form(oscillator_plane):
    out, _, summary = oscillator_plane
    k, c, d = 1.0, 0.1, 1.0
    grazing = [g for g in summary["curves"] if g["type"] == "grazing"]
    assert len(grazing) == 1
    assert "from special point 2 (GR): on curve %d" % grazing[0]["id"] in summary["report"]
    rows = curve_rows(out, grazing[0])
    assert list(rows[0])[:2] == ["w", "A"]
    assert min(r["w"] for r in rows) == pytest.approx(0.7) and max(r["w"] for r in rows) == pytest.approx(1.3)
    for r in rows:
        assert r["A"] == pytest.approx(d * math.hypot(k - r["w"] ** 2, c * r["w"]), abs=1e-9)
    lowest = [q for q in grazing[0]["codim_two"] if q["type"] == "turning" and q["name"] == "A"]
    assert len(lowest) == 1
    assert lowest[0]["w"] == pytest.approx(math.sqrt(k - c * c / 2), abs=1e-9)
    assert lowest[0]["A"] == pytest.approx(d * c * math.sqrt(k - c * c / 4), abs=1e-9)


def test_period_doubling_curve_of_the_impact_oscillator_meets_a_run_at_another_amplitude(oscillator_plane,
                                                                                           tmp_path):
    out, model, summary = oscillator_plane
    pd = next(g for g in summary["curves"] if g["type"] == "period-doubling")
    # On the stretch of the curve that leaves the run's PD (w = 0.985 at A = 0.3) towards larger amplitudes.
    rows = [r for r in curve_rows(out, pd) if r["w"] > 0.95]
    at = nearest(rows, "A", 0.4)
    there = run(tmp_path, model, "--set", "A=%.17g" % at["A"])
    found = [sp for sp in there["special_points"] if sp["type"] == "PD" and sp["status"] == "located"]
    assert found
    best = min(found, key=lambda sp: abs(sp["w"] - at["w"]))
    assert abs(best["w"] - at["w"]) <= best["precision"], (best["w"], at["w"], best["precision"])
