"""The bipedal spring-mass model's gaits against an independent integration (SciPy's DOP853).

`hybridcont run models/bipedal-slip.toml` explores walking and running; this test takes physical orbits of
both gaits at three energies each from the branch files and simulates the automaton from their state at the
section with its own code: the equations written out here, every guard out of the current mode watched, the
first one crossed from above taken (as the automaton's semantics says; a guard on or below 0 where a leg
begins is armed only once it has been positive). The simulation must take the orbit's word and come back to
its state after its period.

Environment: HYBRIDCONT_BIN (the hybridcont executable), HYBRIDCONT_MODELS (the models folder).
"""
import csv
import json
import math
import os
import subprocess

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

BIN = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
MODELS = os.environ.get("HYBRIDCONT_MODELS", "models")

# Parameters of models/bipedal-slip.toml (m = l0 = g = 1).
K, BETA, G = 20.0, 0.36, 1.0
S, C = math.sin(BETA), math.cos(BETA)
ARMING = 1e-8  # a guard at most this where a leg begins is on it, not above it


def stance(t, s):
    x, y, dx, dy = s
    f = K * (1 / math.hypot(x, y) - 1)
    return [dx, dy, f * x, f * y - G]


def double(t, s):
    x, y, dx, dy, d = s
    f1 = K * (1 / math.hypot(x, y) - 1)
    f2 = K * (1 / math.hypot(x - d, y) - 1)
    return [dx, dy, f1 * x + f2 * (x - d), (f1 + f2) * y - G, 0.0]


def flight(t, s):
    return [s[2], 0.0, -G]


# Per mode: vector field, and the transitions out of it: (name, guard, target mode, reset).
MODES = {
    "stance": (stance, [
        ("touchdown", lambda s: s[1] - C, "double", lambda s: [s[0], s[1], s[2], s[3], s[0] + S]),
        ("liftoff", lambda s: 1 - math.hypot(s[0], s[1]), "flight", lambda s: [s[1], s[2], s[3]]),
    ]),
    "double": (double, [
        ("rear_off", lambda s: 1 - math.hypot(s[0], s[1]), "stance", lambda s: [s[0] - s[4], s[1], s[2], s[3]]),
        ("front_off", lambda s: 1 - math.hypot(s[0] - s[4], s[1]), "stance", lambda s: list(s[:4])),
    ]),
    "flight": (flight, [
        ("landing", lambda s: s[0] - C, "stance", lambda s: [-S, s[0], s[1], s[2]]),
    ]),
}
ANCHOR = ("anchor", lambda s: -s[0], None, None)  # mid-stance: x crosses 0 upward


def first_crossing(rhs, x0, watched, horizon=20.0, chunk=0.5, grid=400):
    """The first guard crossed from above: (index, time, state)."""
    armed = [g(x0) > ARMING for _, g, _, _ in watched]
    t0, x = 0.0, np.array(x0, float)
    while t0 < horizon:
        sol = solve_ivp(rhs, [t0, t0 + chunk], x, method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)
        ts = np.linspace(t0, t0 + chunk, grid)
        values = [[g(sol.sol(t)) for _, g, _, _ in watched] for t in ts]
        for a in range(1, grid):
            hits = []
            for j in range(len(watched)):
                before, after = values[a - 1][j], values[a][j]
                if armed[j] and before > 0 and after <= 0:
                    g = watched[j][1]
                    hits.append((brentq(lambda t: g(sol.sol(t)), ts[a - 1], ts[a], xtol=1e-15, rtol=1e-15), j))
                if after > 0:
                    armed[j] = True
            if hits:
                t, j = min(hits)
                return j, t, sol.sol(t)
        t0, x = t0 + chunk, sol.y[:, -1]
    raise AssertionError("no guard crossed")


def replay(x1, legs):
    """Simulates the automaton from the section state x1 (mode stance); the transitions taken, the time to
    the section after `legs` transitions, and the state there."""
    mode, x, t, taken = "stance", list(x1), 0.0, []
    for leg in range(legs + 1):
        rhs, out = MODES[mode]
        watched = list(out) + ([ANCHOR] if leg == legs else [])
        j, dt, x_end = first_crossing(rhs, x, watched)
        t += dt
        name, _, target, reset = watched[j]
        if name == "anchor":
            return taken, t, np.array(x_end)
        taken.append(name)
        if leg == legs:
            return taken, t, np.array(x_end)
        mode, x = target, reset(list(x_end))
    raise AssertionError("unreachable")


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    out = tmp_path_factory.mktemp("bipedal")
    subprocess.run([BIN, "run", os.path.join(MODELS, "bipedal-slip.toml"), "--out", str(out), "--quiet",
                    "--no-plots"], check=True, stdout=subprocess.DEVNULL)
    with open(out / "summary.json") as f:
        summary = json.load(f)
    return out, summary


def physical_points(out, summary, word):
    points = []
    for b in summary["branches"]:
        if b.get("word") != word:
            continue
        with open(out / b["file"]) as f:
            for row in csv.DictReader(f):
                if row["physical"] == "1":
                    points.append({k: float(row[k]) for k in row if k == "H" or k[0] in "tx" and k[1].isdigit()})
    return points


@pytest.mark.parametrize("word,transitions", [
    (["stance", "double", "stance", "double"], ["touchdown", "rear_off", "touchdown", "rear_off"]),
    (["stance", "flight", "stance", "flight"], ["liftoff", "landing", "liftoff", "landing"]),
])
def test_gait_periods_match_an_independent_integration_at_three_energies(results, word, transitions):
    out, summary = results
    points = physical_points(out, summary, word)
    assert len(points) >= 3, f"fewer than three physical orbits of {word}"
    levels = sorted({round(p["H"], 6): p for p in points}.items())
    chosen = [levels[0][1], levels[len(levels) // 2][1], levels[-1][1]]
    assert chosen[-1]["H"] - chosen[0]["H"] > 1e-3  # three distinct energies
    for p in chosen:
        x1 = [p["x1_x"], p["x1_y"], p["x1_dx"], p["x1_dy"]]
        period = sum(p[f"t{i}"] for i in range(1, 6))
        taken, t, x_end = replay(x1, len(transitions))
        assert taken == transitions
        assert abs(t - period) < 1e-8 * max(1.0, period), (p["H"], t, period)
        assert np.max(np.abs(x_end - np.array(x1))) < 1e-8, (p["H"], x_end, x1)


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
    assert count >= 100
