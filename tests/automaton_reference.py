"""An independent event-driven simulation of a hybrid automaton (SciPy's DOP853), for the reference tests.

A mode is (vector field, transitions); a transition is (name, guard, target mode, reset). From a state, the
flow runs until the first guard among the mode's transitions is crossed from above (a guard on or below 0
where a leg begins is armed once it has been positive, as hybridcont's automata), located by Brent's method
on the dense output; the transition's reset gives the next mode's state.
"""
import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

ARMING = 1e-8  # a guard at most this where a leg begins is on it, not above it


def first_crossing(rhs, x0, watched, horizon=20.0, chunk=0.5, grid=400):
    """The first guard of `watched` crossed from above: (index, time, state)."""
    armed = [g(x0) > ARMING for _, g, _, _ in watched]
    t0, x = 0.0, np.array(x0, float)
    while t0 < horizon:
        sol = solve_ivp(rhs, [t0, t0 + chunk], x, method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)
        ts = np.linspace(t0, t0 + chunk, grid)
        states = sol.sol(ts)  # the dense output at every grid time at once (one call, not `grid`)
        values = [[g(states[:, k]) for _, g, _, _ in watched] for k in range(grid)]
        for k in range(1, grid):
            hits = []
            for j in range(len(watched)):
                if armed[j] and values[k - 1][j] > 0 and values[k][j] <= 0:
                    g = watched[j][1]
                    hits.append((brentq(lambda t: g(sol.sol(t)), ts[k - 1], ts[k], xtol=1e-15, rtol=1e-15), j))
                if values[k][j] > 0:
                    armed[j] = True
            if hits:
                t, j = min(hits)
                return j, t, sol.sol(t)
        t0, x = t0 + chunk, sol.y[:, -1]
    raise AssertionError("no guard crossed")


def replay(modes, anchor, mode, x1, legs, horizon=20.0):
    """Simulates from the section state x1 in `mode`: the transitions taken, the time to the section (the
    anchor's crossing, watched after `legs` transitions) and the state there. A leg longer than `horizon`
    raises AssertionError."""
    x, t, taken = list(x1), 0.0, []
    for leg in range(legs + 1):
        rhs, out = modes[mode]
        watched = list(out) + ([anchor] if leg == legs else [])
        j, dt, x_end = first_crossing(rhs, x, watched, horizon=horizon)
        t += dt
        name, _, target, reset = watched[j]
        if name == "anchor" or leg == legs:
            return taken + ([] if name == "anchor" else [name]), t, np.array(x_end)
        taken.append(name)
        mode, x = target, reset(list(x_end))
    raise AssertionError("unreachable")


def physical_points(out, summary, word):
    """The physical points of the branches of `word`: H, durations and states by column name."""
    import csv
    points = []
    for b in summary["branches"]:
        if b.get("word") != word:
            continue
        with open(out / b["file"]) as f:
            points += [{k: float(r[k]) for k in r if k == "H" or k[0] in "tx" and k[1].isdigit()}
                       for r in csv.DictReader(f) if r["physical"] == "1"]
    return points


def three_energies(points):
    """The physical points at the lowest, middle and highest of their energies."""
    levels = sorted({round(p["H"], 6): p for p in points}.items())
    return [levels[0][1], levels[len(levels) // 2][1], levels[-1][1]]


def run_model(binary, model_file, out):
    """`hybridcont run` of a model file into `out` (quiet, no figures); its summary.json."""
    import json
    import subprocess
    subprocess.run([binary, "run", str(model_file), "--out", str(out), "--quiet", "--no-plots"], check=True,
                   stdout=subprocess.DEVNULL)
    with open(out / "summary.json") as f:
        return json.load(f)


def check_periods_at_three_energies(out, summary, word, transitions, modes, anchor, states):
    """Physical orbits of `word` at three energies, simulated from their section state (columns x1_<state>):
    the automaton takes `transitions` and returns to the state after the orbit's period, both to 1e-8."""
    points = physical_points(out, summary, word)
    assert len(points) >= 3, f"fewer than three physical orbits of {word}"
    chosen = three_energies(points)
    assert chosen[-1]["H"] - chosen[0]["H"] > 1e-3  # three distinct energies
    m = len(transitions)
    for p in chosen:
        x1 = [p[f"x1_{s}"] for s in states]
        period = sum(p[f"t{i}"] for i in range(1, m + 2))
        taken, t, x_end = replay(modes, anchor, "stance", x1, m)
        assert taken == transitions
        assert abs(t - period) < 1e-8 * max(1.0, period), (p["H"], t, period)
        assert np.max(np.abs(x_end - np.array(x1))) < 1e-8, (p["H"], x_end, x1)


def model_run_fixture(binary, model_file):
    """A module-scoped pytest fixture `results`: (results folder, summary) of one run of `model_file`."""
    import pytest

    @pytest.fixture(scope="module")
    def results(tmp_path_factory):
        out = tmp_path_factory.mktemp("run")
        return out, run_model(binary, model_file, out)
    return results
