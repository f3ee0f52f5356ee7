"""Where symmetric running of the bipedal spring-mass model loses its flight, against an independent integration.

`hybridcont run models/bipedal-slip.toml --set k=20 --set beta=<22 degrees>` (alpha0 = 68 degrees) carries the
file's starts from its own parameters to these and continues running up in H until its flight phase vanishes:
the physical range of a running branch ends there at a ZD point (a phase of zero duration, located). That level
is computed here without hybridcont: the stance from landing at (-l0 sin b, l0 cos b) with horizontal speed v
and no vertical speed (the apex of a flight of zero duration) passes mid-stance with dy = 0, so it lifts off at
the mirror point with dy = 0 again; H = v^2/2 + g l0 cos b (both springs at rest). v is bracketed by a scan of
the mid-stance vertical speed and refined by Brent's method on SciPy's DOP853 at 1e-13 (about 2.920658327428
here; DOP853 at 1e-14 and Radau agree with it to 1e-11). The tool's ZD level must agree to 1e-8: it is an
ill-conditioned root (dy at mid-stance moves by 0.01 per unit of v there), so hybridcont's default tolerances
put it about 7e-10 off.

The run is kept cheap with --max-branches 2: each start is continued in both directions and nothing further
(about 1 s), which reaches the flight-zero end of running.

Environment: HYBRIDCONT_BIN (the hybridcont executable), HYBRIDCONT_MODELS (the models folder).
"""
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

K, BETA = 20.0, math.radians(22)  # alpha0 = 68 degrees; m = l0 = g = 1
S, C = math.sin(BETA), math.cos(BETA)
RUNNING = ["stance", "flight", "stance", "flight"]


def stance(t, s):
    x, y, dx, dy = s
    f = K * (1 / math.hypot(x, y) - 1)
    return [dx, dy, f * x, f * y - 1]


def dy_at_midstance(v, tol=1e-13):
    """The vertical speed where the stance from landing at (-sin b, cos b) with velocity (v, 0) passes over
    the foot (x = 0); None if the leg is back at rest length (lift-off) first."""
    mid = lambda t, s: s[0]
    mid.terminal, mid.direction = True, 1
    liftoff = lambda t, s: 1 - math.hypot(s[0], s[1])
    liftoff.terminal, liftoff.direction = True, -1
    sol = solve_ivp(stance, [0, 50], [-S, C, v, 0.0], events=[mid, liftoff], method="DOP853", rtol=tol, atol=tol)
    if sol.t_events[0].size == 0 or (sol.t_events[1].size and sol.t_events[1][0] < sol.t_events[0][0]):
        return None
    return sol.y_events[0][0][3]


def zero_flight_levels():
    """Every level where symmetric running has a flight of zero duration, v scanned over [0.2, 6]."""
    vs = np.linspace(0.2, 6.0, 59)
    values = [dy_at_midstance(v, 1e-11) for v in vs]
    levels = []
    for a, b, fa, fb in zip(vs[:-1], vs[1:], values[:-1], values[1:]):
        if fa is not None and fb is not None and (fa > 0) != (fb > 0):
            v = brentq(dy_at_midstance, a, b, xtol=1e-15, rtol=1e-15)
            levels.append(0.5 * v * v + C)
    return levels


@pytest.fixture(scope="module")
def summary(tmp_path_factory):
    out = tmp_path_factory.mktemp("zero_flight") / "run"
    subprocess.run([BIN, "run", os.path.join(MODELS, "bipedal-slip.toml"), "--set", f"k={K!r}",
                    "--set", f"beta={BETA!r}", "--bound", "H=0.9:3.2", "--max-branches", "2",
                    "--out", str(out), "--quiet", "--no-plots"], check=True, stdout=subprocess.DEVNULL)
    with open(out / "summary.json") as f:
        return json.load(f)


def test_the_zero_flight_level_is_a_single_root_near_2_92():
    levels = zero_flight_levels()
    assert len(levels) == 1, levels
    assert abs(levels[0] - 2.920658327427624) < 1e-9


def test_the_start_was_carried_to_the_new_parameters(summary):
    note = summary["start_note"]
    assert "carried" in note and "to 20, 0.383972" in note, note
    assert summary["parameters"]["k"] == K and summary["parameters"]["beta"] == BETA


def test_running_ends_where_its_flight_vanishes_at_the_independent_level(summary):
    """The ZD point is located at the independent level. The physical range of its branch ends there, or one
    point short of it: a point whose flight is a few 1e-4 long belongs to an orbit so unstable (|mu| ~ 1e5) that
    the event-driven replay cannot confirm it (its landing guard rises by a few 1e-9 while the replay's state
    is 1e-6 off): that point is replay-failed and the range ends between the last confirmed point and it."""
    families = {f["name"]: f for f in summary["families"]}
    assert "running" in families, list(families)
    zds = [p for p in summary["special_points"] if p["type"] == "ZD" and p.get("duplicate_of", -1) == -1]
    assert len(zds) == 1, zds
    zd = zds[0]
    assert zd["status"] == "located" and "phase 'flight' of duration 0" in zd["message"]
    (level,) = zero_flight_levels()
    assert abs(zd["H"] - level) < 1e-8, (zd["H"], level)
    branch = next(b for b in summary["branches"] if b["id"] == zd["branch"])
    assert branch["family"] == "running" and branch["word"] == RUNNING
    ends = [r for r in branch["physical_ranges"] if r["to_special_point"] == zd["id"]
            or r["to_how"] == f"between points {zd['index'] - 1} and {zd['index']}, not located"]
    assert len(ends) == 1, branch["physical_ranges"]
    assert abs(ends[0]["to"] - level) < 0.1, ends
