"""The region of self-stable spring-mass running (Seyfarth et al. 2002) as curves, against the apex return map.

models/slip-running.toml at the energy H = 2.28 (an apex 1 high at 5 m/s for 80 kg and a leg of 1 m) with the
stiffness k free and the curves in the touch-down angle beta (`--free k --fix H=2.28 --curves beta`): running is
stable between its period doubling (the lower k) and its fold (the upper k, where the stable and the unstable
gait meet and end), and the region between the two curves is written as a polygon (summary.json "regions").

The reference is independent of the tool: Seyfarth et al.'s own method, the one-dimensional map from apex
height to apex height at fixed energy, integrated in Cartesian coordinates with SciPy (slip_running_reference.py);
running is stable where the map has a fixed point of slope below 1 in size.

1. At three touch-down angles, the PD and the fold a one-parameter run locates: the reference's class changes
   there (stable 1e-4 inside, unstable or no gait 1e-4 outside), and the curves pass through both.
2. Cells of the (beta, k) plane away from the curves: stable by the reference exactly where inside the
   region's polygon.

Environment: HYBRIDCONT_BIN (the hybridcont executable), HYBRIDCONT_MODELS (the shipped model files).
"""
import csv
import json
import os
import subprocess
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import slip_running_reference as reference  # noqa: E402

BIN = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
MODEL = os.path.join(os.environ.get("HYBRIDCONT_MODELS", "models"), "slip-running.toml")
ENERGY = 2.28
DELTA = 1e-4  # relative distance from a located boundary at which the reference must tell its side


def run(out, *args):
    done = subprocess.run([BIN, "run", MODEL, *args, "--out", str(out), "--quiet"], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr + done.stdout
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)


@pytest.fixture(scope="module")
def plane(tmp_path_factory):
    out = tmp_path_factory.mktemp("slip_running_plane")
    summary = run(out, "--free", "k", "--fix", "H=%g" % ENERGY, "--curves", "beta")
    curves = {}
    for c in summary["curves"]:
        with open(os.path.join(out, c["file"]), newline="") as f:
            rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
        curves.setdefault(c["type"], []).append(sorted(((r["beta"], r["k"]) for r in rows)))
    return summary, curves


def curve_k(curve, beta):
    """k of a curve (beta increasing along it) at beta, linearly interpolated."""
    b, k = np.array(curve).T
    assert b[0] <= beta <= b[-1]
    return float(np.interp(beta, b, k))


def test_the_plane_has_the_fold_and_the_period_doubling_and_the_stable_region(plane):
    summary, curves = plane
    assert len(curves["fold"]) == 1 and len(curves["period-doubling"]) == 1
    stable = [r for r in summary["regions"] if r["family"] == "running" and r["kind"] == "stable"]
    assert len(stable) == 1 and len(stable[0]["polygon"]) > 100


@pytest.mark.parametrize("beta", [0.30, 0.3839724354387525, 0.45])
def test_located_boundaries_are_where_the_apex_map_changes_class(plane, tmp_path, beta):
    _, curves = plane
    # A stiffness inside the region at this angle (from the curves), where running exists at the energy.
    inside = 0.5 * (curve_k(curves["period-doubling"][0], beta) + curve_k(curves["fold"][0], beta))
    summary = run(tmp_path, "--set", "beta=%.17g" % beta, "--set", "k=%.17g" % inside, "--free", "k", "--fix",
                  "H=%g" % ENERGY)
    located = {sp["type"]: sp["k"] for sp in summary["special_points"] if sp["status"] == "located"
               and sp["type"] in ("PD", "TP")}
    k_pd, k_fold = located["PD"], located["TP"]
    assert k_pd < k_fold
    assert reference.stable_running(k_pd * (1 + DELTA), beta, ENERGY) is True
    assert reference.stable_running(k_pd * (1 - DELTA), beta, ENERGY) is False  # a fixed point, flipped
    assert reference.stable_running(k_fold * (1 - DELTA), beta, ENERGY) is True
    assert reference.stable_running(k_fold * (1 + DELTA), beta, ENERGY) is None  # no running gait at all
    # The curves pass through the one-parameter run's points (to their linear interpolation between samples).
    assert curve_k(curves["period-doubling"][0], beta) == pytest.approx(k_pd, rel=2e-3)
    assert curve_k(curves["fold"][0], beta) == pytest.approx(k_fold, rel=2e-3)


def inside_polygon(x, y, polygon):
    """Even-odd rule."""
    inside = False
    for (x1, y1), (x2, y2) in zip(polygon, polygon[1:] + polygon[:1]):
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


def test_cells_of_the_plane_are_stable_exactly_inside_the_region(plane):
    summary, curves = plane
    polygon = next(r["polygon"] for r in summary["regions"] if r["family"] == "running" and r["kind"] == "stable")
    checked = 0
    for beta in (0.28, 0.36, 0.44):
        k_pd, k_fold = curve_k(curves["period-doubling"][0], beta), curve_k(curves["fold"][0], beta)
        for k in (0.9 * k_pd, 0.75 * k_pd + 0.25 * k_fold, 0.25 * k_pd + 0.75 * k_fold, 1.1 * k_fold):
            expected = inside_polygon(beta, k, polygon)
            assert expected == (k_pd < k < k_fold)
            assert (reference.stable_running(k, beta, ENERGY) is True) == expected, (beta, k)
            checked += 1
    assert checked == 12
