"""A family whose period grows without bound: the rimless wheel's gait at its smallest slope, against closed forms.

The rimless wheel (McGeer 1990; g = l = 1): a stance spoke at angle theta from the slope's normal falls forward
as theta'' = sin(theta + gamma); where theta reaches alpha the next spoke strikes, theta -> -alpha and the
angular speed is multiplied by c = cos(2 alpha). Its steady gait exists on slopes gamma above gamma*, where the
wheel coming off an impact just reaches the top (theta = -gamma) with speed zero: energy (1/2 w^2 + cos(theta +
gamma)) conserved in the stance gives (1 - cos(alpha - gamma)) / c^2 = 1 - cos(alpha + gamma), a closed form for
gamma*. Towards it the period grows without bound (the orbit lingers at the unstable equilibrium on top), the
monodromy grows like e^T and its computed entries lose their digits: the multipliers scatter, the replay finds
crossings early or late, and Newton finally cannot converge. The only multiplier is c^2 on every orbit (the
stance conserves energy; only the impact takes it).

What the tool must say there: the family's orbits up to the last one the integration resolves (its multipliers'
estimated error below 1e-3), the range ending exactly at it and saying so, no special point and no stability
word that the multipliers contradict, and each multiplier within its stated error of c^2. The period at each
resolved orbit agrees with the closed-form quadrature.

Environment: HYBRIDCONT_BIN (the hybridcont executable).
"""
import csv
import json
import math
import os
import subprocess

import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

BIN = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
ALPHA = 0.3
C = math.cos(2 * ALPHA)

MODEL = """hybridcont = 1
name = "rimless-wheel"
title = "rimless wheel"
conservative = false

[parameters]
gamma = { value = 0.08, range = "[0, 0.5]", description = "slope angle [rad]" }
alpha = { value = 0.3, range = "(0, 1.5)", description = "half the angle between spokes [rad]" }

[[phases]]
name = "stance"
states = ["theta", "dtheta"]
typical = [0.0, 0.5]
ode = { theta = "dtheta", dtheta = "sin(theta + gamma)" }
event = "alpha - theta"
anchor = "-theta"
reset = { theta = "-alpha", dtheta = "cos(2*alpha)*dtheta" }

[start]
kind = "simulation"
values = { x1_theta = 0, x1_dtheta = 0.6 }

[run]
parameter = "gamma"
bounds = { gamma = [0.0, 0.3], period = [0, 200] }
"""


def smallest_slope():
    return brentq(lambda g: (1 - math.cos(ALPHA - g)) / C**2 - (1 - math.cos(ALPHA + g)), 1e-3, 0.2, xtol=1e-16)


def period(gamma):
    """From the impact (theta = -alpha, speed w+) to the next (theta = alpha): the steady gait's w-^2 =
    4 sin(alpha) sin(gamma) / (1 - c^2) from the energy balance, w+ = c w-."""
    w_plus2 = C**2 * 4 * math.sin(ALPHA) * math.sin(gamma) / (1 - C**2)
    speed = lambda th: math.sqrt(w_plus2 + 2 * (math.cos(gamma - ALPHA) - math.cos(th + gamma)))
    top = -gamma  # the slowest point: split the integral there
    a, _ = quad(lambda th: 1 / speed(th), -ALPHA, top, epsabs=1e-13, epsrel=1e-13, limit=200)
    b, _ = quad(lambda th: 1 / speed(th), top, ALPHA, epsabs=1e-13, epsrel=1e-13, limit=200)
    return a + b


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("wheel")
    model = folder / "rimless-wheel.toml"
    model.write_text(MODEL)
    out = folder / "run"
    subprocess.run([BIN, "run", str(model), "--out", str(out), "--quiet", "--no-plots"], check=True,
                   stdout=subprocess.DEVNULL)
    with open(out / "summary.json") as f:
        summary = json.load(f)
    rows = {}
    for b in summary["branches"]:
        with open(out / b["file"]) as f:
            rows[b["id"]] = list(csv.DictReader(f))
    return summary, rows


def test_the_family_ends_at_its_last_resolved_orbit_just_above_the_smallest_slope(run):
    summary, rows = run
    (family,) = summary["families"]
    (physical,) = family["physical"]
    (stable,) = family["stable"]
    g_star = smallest_slope()
    assert abs(g_star - 0.028921913954) < 1e-11
    assert physical["from_end"].endswith("the last orbit the integration resolves"), physical
    assert 0 < physical["from"] - g_star < 1e-8, (physical["from"], g_star)
    assert stable == physical  # stable throughout: the multiplier is c^2 = 0.68
    # No special point anywhere: the multiplier never moves.
    assert summary["special_points"] == [], summary["special_points"]


def test_every_resolved_orbit_has_the_closed_form_multiplier_and_period(run):
    summary, rows = run
    checked = 0
    for b in summary["branches"]:
        for r in rows[b["id"]]:
            if r["physical"] != "1" or float(r["multiplier_error"]) > 1e-3:
                continue
            mu, error = float(r["mu1_re"]), float(r["multiplier_error"])
            # The multipliers are those of the corrector's last iterate, within 1e-7 relative of the point's
            # own (docs/results-format.md), then off by the monodromy's error at that iterate.
            assert abs(mu - C**2) <= error + 1e-7 * C**2, (r["index"], mu, error)
            assert r["stability"] == "asymptotically stable"
            gamma, T = float(r["gamma"]), float(r["T"])
            if T < 10:  # beyond, T moves by e^T per unit of gamma: the quadrature's gamma is the limit
                assert abs(T - period(gamma)) < 1e-8 * T, (gamma, T, period(gamma))
            checked += 1
    assert checked > 100


def test_orbits_beyond_are_in_the_files_but_in_no_range(run):
    """The unresolved orbits nearer the smallest slope are kept as data, with their multipliers' error, and the
    branch says why it stopped."""
    summary, rows = run
    lower = min(summary["branches"], key=lambda b: min(float(r["gamma"]) for r in rows[b["id"]]))
    errors = [float(r["multiplier_error"]) for r in rows[lower["id"]] if r["physical"] == "1"]
    assert max(errors) > 1e-3
    last = lower["physical_ranges"][0]["last_point"]
    assert float(rows[lower["id"]][last + 1]["multiplier_error"]) > 1e-3
    assert float(rows[lower["id"]][last + 1]["T"]) > float(rows[lower["id"]][last]["T"])
