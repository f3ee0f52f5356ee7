"""The bipedal spring-mass model with swing legs against an independent integration (SciPy's DOP853).

`hybridcont run models/bipedal-slip-swing.toml` explores walking and running; physical orbits of both at
three energies each are simulated here from their state at the section as the automaton: the equations
written out again, every guard out of the current mode watched, the first one crossed from above taken (a
guard on or below 0 where a leg begins is armed once it has been positive). The simulation must take the
orbit's word and return to its state after its period.

Environment: HYBRIDCONT_BIN (the hybridcont executable), HYBRIDCONT_MODELS (the models folder).
"""
import math
import os

import pytest

from automaton_reference import check_periods_at_three_energies, model_run_fixture

BIN = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
MODELS = os.environ.get("HYBRIDCONT_MODELS", "models")

# Parameters of models/bipedal-slip-swing.toml (m = l0 = g = 1).
K, W2, EPS, G = 20.0, 5.0, 0.01, 1.0


def foot(y, a):
    """The touch-down guard: the foot's height ahead of the hip, <= 0 behind it."""
    ahead = 0.5 * (1 + math.tanh(a / EPS))
    h = y - math.cos(a)
    return h * ahead - (1 - ahead) * h * h


def angle(x, y, dx, dy):
    """A leg's angle from the vertical (foot at the origin, body at (x, y)) and its rate."""
    return math.atan2(-x, y), (x * dy - y * dx) / (x * x + y * y)


def stance(t, s):
    x, y, dx, dy, a, da = s
    f = K * (1 / math.hypot(x, y) - 1)
    return [dx, dy, f * x, f * y - G, da, -W2 * a]


def double(t, s):
    x, y, dx, dy, d = s
    f1 = K * (1 / math.hypot(x, y) - 1)
    f2 = K * (1 / math.hypot(x - d, y) - 1)
    return [dx, dy, f1 * x + f2 * (x - d), (f1 + f2) * y - G, 0.0]


def flight(t, s):
    y, dx, dy, a, da, b, db = s
    return [dy, 0.0, -G, da, -W2 * a, db, -W2 * b]


MODES = {
    "stance": (stance, [
        ("touchdown", lambda s: foot(s[1], s[4]), "double", lambda s: [s[0], s[1], s[2], s[3], s[0] + math.sin(s[4])]),
        ("liftoff", lambda s: 1 - math.hypot(s[0], s[1]), "flight",
         lambda s: [s[1], s[2], s[3], s[4], s[5], *angle(s[0], s[1], s[2], s[3])]),
    ]),
    "double": (double, [
        ("rear_off", lambda s: 1 - math.hypot(s[0], s[1]), "stance",
         lambda s: [s[0] - s[4], s[1], s[2], s[3], *angle(s[0], s[1], s[2], s[3])]),
        ("front_off", lambda s: 1 - math.hypot(s[0] - s[4], s[1]), "stance",
         lambda s: [s[0], s[1], s[2], s[3], *angle(s[0] - s[4], s[1], s[2], s[3])]),
    ]),
    "flight": (flight, [
        ("land_a", lambda s: foot(s[0], s[3]), "stance", lambda s: [-math.sin(s[3]), s[0], s[1], s[2], s[5], s[6]]),
        ("land_b", lambda s: foot(s[0], s[5]), "stance", lambda s: [-math.sin(s[5]), s[0], s[1], s[2], s[3], s[4]]),
    ]),
}
ANCHOR = ("anchor", lambda s: -s[0], None, None)  # mid-stance


results = model_run_fixture(BIN, os.path.join(MODELS, "bipedal-slip-swing.toml"))


@pytest.mark.parametrize("word,transitions", [
    (["stance", "double", "stance", "double"], ["touchdown", "rear_off", "touchdown", "rear_off"]),
    (["stance", "flight", "stance", "flight"], ["liftoff", "land_a", "liftoff", "land_a"]),
])
def test_gait_periods_match_an_independent_integration_at_three_energies(results, word, transitions):
    check_periods_at_three_energies(*results, word, transitions, MODES, ANCHOR, ("x", "y", "dx", "dy", "a", "da"))