"""The bipedal spring-mass model's gaits against an independent integration (SciPy's DOP853).

`hybridcont run` of models/bipedal-slip.toml at k = 20, beta = 0.36 (a variant where running loses its flight
inside the diagram) explores walking and running; this test takes physical orbits of
both gaits at three energies each from the branch files and simulates the automaton from their state at the
section with its own code: the equations written out here, every guard out of the current mode watched, the
first one crossed from above taken (as the automaton's semantics says; a guard on or below 0 where a leg
begins is armed only once it has been positive). The simulation must take the orbit's word and come back to
its state after its period.

Environment: HYBRIDCONT_BIN (the hybridcont executable), HYBRIDCONT_MODELS (the models folder).
"""
import csv
import math
import os

import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from automaton_reference import check_periods_at_three_energies
from bipedal_slip_model import Biped

BIN = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
MODELS = os.environ.get("HYBRIDCONT_MODELS", "models")

# Parameters of the variant of models/bipedal-slip.toml below (m = l0 = g = 1).
K, BETA, G = 20.0, 0.36, 1.0
S, C = math.sin(BETA), math.cos(BETA)


BIPED = Biped(K, BETA)
stance, MODES = BIPED.stance, BIPED.modes
ANCHOR = BIPED.anchor  # mid-stance: x crosses 0 upward


# The shipped file with a softer leg and a steeper touch-down angle, where running loses its flight inside the
# diagram (at the shipped parameters, Geyer et al.'s, running folds at H = 1.872 before its flight vanishes):
# k = 20, beta = 0.36, and a running start at H = 1.4965 (speed 1 at mid-stance) found as the shipped ones
# are (scipy, the step map's root in the mid-stance height).
RUNNING_START = (
    "values = { H = 1.4964964294173033, t1 = 0.34293202890344493, x1_x = 0, x1_y = 0.9036357579410815, "
    "x1_dx = 1.0000000000003235, x1_dy = 0, t2 = 0.14381740620960234, x2_y = 0.9358968236779563, "
    "x2_dx = 1.056422429663647, x2_dy = 0.07190870310465161, t3 = 0.6858640578070607, x3_x = -0.35227423327508994, "
    "x3_y = 0.9358968236779348, x3_dx = 1.056422429663647, x3_dy = -0.0719087031049507, t4 = 0.14381740620932057, "
    "x4_y = 0.9358968236779375, x4_dx = 1.0564224296635156, x4_dy = 0.0719087031046415, t5 = 0.34293202890356705, "
    "x5_x = -0.35227423327508994, x5_y = 0.9358968236779348, x5_dx = 1.0564224296635156, "
    "x5_dy = -0.07190870310467905 }")


def variant_model(tmp_dir):
    """models/bipedal-slip.toml at k = 20, beta = 0.36 with the running start above (the walking start stays:
    Newton finds the walking family through it at these parameters too)."""
    text = open(os.path.join(MODELS, "bipedal-slip.toml")).read()
    lines = text.split("\n")
    for i, line in enumerate(lines):
        if line.startswith("k    = "):
            lines[i] = 'k    = { value = 20.0, range = "(0, inf)" }'
        elif line.startswith("beta = "):
            lines[i] = 'beta = { value = 0.36, range = "(0, 1.5)" }'
        elif line.startswith("values = { H = 2.0,"):
            lines[i] = RUNNING_START
    path = tmp_dir / "bipedal-slip.toml"
    path.write_text("\n".join(lines))
    return path


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    from automaton_reference import run_model
    folder = tmp_path_factory.mktemp("variant")
    out = folder / "run"
    return out, run_model(BIN, variant_model(folder), out)


@pytest.mark.parametrize("word,transitions", [
    (["stance", "double", "stance", "double"], ["touchdown", "rear_off", "touchdown", "rear_off"]),
    (["stance", "flight", "stance", "flight"], ["liftoff", "landing", "liftoff", "landing"]),
])
def test_gait_periods_match_an_independent_integration_at_three_energies(results, word, transitions):
    check_periods_at_three_energies(*results, word, transitions, MODES, ANCHOR, ("x", "y", "dx", "dy"))


def zero_flight_level():
    """The level where symmetric running loses its flight: the stance from landing at (-l0 sin b, l0 cos b)
    with a horizontal velocity v passes mid-stance with dy = 0, so it lifts off with dy = 0 at the mirror
    point; H = v^2 / 2 + g l0 cos b (both springs at rest)."""
    def dy_at_midstance(v):
        mid = lambda t, s: s[0]
        mid.terminal, mid.direction = True, 1
        sol = solve_ivp(stance, [0, 10], [-S, C, v, 0.0], events=mid, method="DOP853", rtol=1e-13, atol=1e-13)
        return sol.y_events[0][0][3]
    v = brentq(dy_at_midstance, 1.0, 1.1, xtol=1e-15)
    return 0.5 * v * v + G * C


def test_running_without_flight_hands_over_to_a_double_support_of_zero_duration(results):
    _, summary = results
    traded = [c for c in summary["word_changes"] if c.get("accepted") and "traded" in c.get("rule", "")]
    assert len(traded) == 1, summary["word_changes"]
    c = traded[0]
    assert c["from_word"] == ["stance", "flight", "stance", "flight"]
    assert c["to_word"] == ["stance", "double", "stance", "flight"]
    assert abs(c["H"] - zero_flight_level()) < 1e-8
    assert c["state_difference"] < 1e-10 and c["period_difference"] < 1e-10


def test_every_physical_orbit_is_replayed_by_the_automaton(results):
    out, summary = results
    count = 0
    for b in summary["branches"]:
        with open(out / b["file"]) as f:
            for row in csv.DictReader(f):
                if row["physical"] == "1":
                    assert float(row["automaton_replay_error"]) < 1e-8, (b["id"], row["index"])
                    count += 1
    assert count >= 80  # 87 physical orbits in the variant's diagram
