"""Every classification of the bipedal spring-mass model against an independent simulation, over (k, beta).

For the shipped file (Geyer et al.'s parameters) and four other pairs of leg stiffness k and touch-down
angle beta, this test finds its own starts (symmetric walking and running: roots of the step map in the
mid-stance height, SciPy's DOP853 and Brent's method), writes them into a copy of models/bipedal-slip.toml,
runs `hybridcont run` and simulates orbits of every branch with the automaton simulator of
automaton_reference.py (every guard watched, the first crossed from above taken):
  - a point the tool calls physical must be confirmed: the simulation from its state at the section takes
    the branch's word and returns to that state after the orbit's period;
  - a point of the conservative system (xi = 0) the tool calls non-physical must not be, but for the classes
    that sit on a boundary (zero-duration, grazing).
Checked: the points on both sides of every end of a physical family (where a wrong class would be), every physical
point with a phase shorter than 0.05 (short flights and double supports), every second physical point and
every 100th point.

The shipped file's walking at Geyer et al.'s E = 820 J is checked against the step map's fixed point and its
multipliers (finite differences of the simulated step map), and its family's ends and stability change
against the located special points.

Environment: HYBRIDCONT_BIN (the hybridcont executable), HYBRIDCONT_MODELS (the models folder).
"""
import csv
import json
import math
import os

import numpy as np
import pytest
from scipy.optimize import brentq

from automaton_reference import replay, run_model
from bipedal_slip_model import Biped

BIN = os.environ.get("HYBRIDCONT_BIN", "build/hybridcont")
MODELS = os.environ.get("HYBRIDCONT_MODELS", "models")

# Geyer et al.'s parameters (k = 20 kN/m for 80 kg and l0 = 1 m at g = 9.81; 69 degrees from the ground).
K_GEYER, BETA_GEYER, H_820J = 20000 / (80 * 9.81), math.radians(21), 820 / (80 * 9.81)


def write_model(folder, k, beta, walking, running):
    """models/bipedal-slip.toml at (k, beta) with the two starts."""
    text = open(os.path.join(MODELS, "bipedal-slip.toml")).read()
    values = lambda v: "values = { " + ", ".join(f"{n} = {float(x)!r}" for n, x in v.items()) + " }"
    lines = text.split("\n")
    starts = 0
    for i, line in enumerate(lines):
        if line.startswith("k    = "):
            lines[i] = f'k    = {{ value = {k!r}, range = "(0, inf)" }}'
        elif line.startswith("beta = "):
            lines[i] = f'beta = {{ value = {beta!r}, range = "(0, 1.5)" }}'
        elif line.startswith("values = { H = "):
            lines[i] = values(walking if starts == 0 else running)
            starts += 1
    assert starts == 2
    path = folder / "bipedal-slip.toml"
    path.write_text("\n".join(lines))
    return path


BOUNDARY_CLASSES = {"zero-duration", "grazing"}


def confirmed(biped, row, word):
    """The simulation from the row's state at the section passes through the modes of `word` (the branch's
    word, by mode) and returns to that state after the orbit's period."""
    x1 = [float(row[f"x1_{s}"]) for s in ("x", "y", "dx", "dy")]
    period = float(row["T"])
    try:
        # No leg of the orbit lasts longer than its period: a simulation that does not end a leg by then is
        # no simulation of this orbit.
        taken, t, x_end = replay(biped.modes, biped.anchor, "stance", x1, len(word), horizon=abs(period) + 0.5)
    except (AssertionError, ValueError):
        return False
    target = {name: to for _, (_, out) in biped.modes.items() for name, _, to, _ in out}
    visited = [target[name] for name in taken]
    return (visited == list(word[1:]) + [word[0]] and abs(t - period) < 1e-7 * max(1.0, period)
            and float(np.max(np.abs(np.array(x_end) - np.array(x1)))) < 1e-7)


def sampled_rows(rows):
    """Indices of the rows to simulate (see the module's docstring)."""
    chosen = set(range(0, len(rows), 100)) | {i for i, row in enumerate(rows) if row["physical"] == "1" and i % 2 == 0}
    for i in range(1, len(rows)):
        if (rows[i]["physical"] == "1") != (rows[i - 1]["physical"] == "1"):  # an end of a physical family
            chosen |= {i - 1, i}
    for i, row in enumerate(rows):
        durations = [float(row[f"t{j}"]) for j in range(1, 6)]
        if row["physical"] == "1" and min(durations) < 0.05:
            chosen.add(i)
    return sorted(chosen)


def check_every_classification(biped, out, summary):
    """Counts (physical confirmed, non-physical refused) over the sampled rows of every branch."""
    physical = refused = 0
    for b in summary["branches"]:
        word = b.get("word", [])
        with open(out / b["file"]) as f:
            rows = list(csv.DictReader(f))
        for i in sampled_rows(rows):
            row = rows[i]
            if row["physical"] == "1":
                assert confirmed(biped, row, word), ("physical, not confirmed", b["id"], row["index"], row["H"])
                physical += 1
            elif row["classification"] not in BOUNDARY_CLASSES and abs(float(row["xi"])) < 1e-9:
                assert not confirmed(biped, row, word), (row["classification"], "confirmed by the simulation",
                                                         b["id"], row["index"], row["H"])
                refused += 1
    return physical, refused


# (k, beta, walking level and mid-stance height bracket, running level and bracket): the brackets hold one
# root of the step map each (found by scanning it).
SETTINGS = [
    (20.0, 0.3839724354, (1.05, 0.975, 0.985), (2.0, 0.90, 0.93)),   # 68 degrees: short running flights
    (15.0, 0.35, (1.05, 0.94, 0.947), (2.0, 0.60, 0.62)),
    (30.0, 0.38, (1.05, 0.98, 0.99), (2.5, 0.88, 0.90)),
    (22.0, 0.33, (1.05, 0.975, 0.985), (2.0, 0.70, 0.72)),
]


@pytest.mark.parametrize("k,beta,walk,run", SETTINGS)
def test_every_classification_is_the_simulation_s(tmp_path, k, beta, walk, run):
    biped = Biped(k, beta)
    walking = biped.walking_start(*walk)
    running = biped.running_start(*run)
    out = tmp_path / "run"
    summary = run_model(BIN, write_model(tmp_path, k, beta, walking, running), out)
    physical, refused = check_every_classification(biped, out, summary)
    print(f"k = {k}, beta = {beta}: {physical} physical orbits confirmed, {refused} non-physical ones refused")
    assert physical >= 10 and refused >= 5
    # A branch abandoned for want of physical orbits has none, and says so.
    for b in summary["branches"]:
        if b["termination"] == "abandoned":
            assert b["message"] in ("no physical orbit over an arclength of 150 of the scenario's largest steps",
                                    "its orbits are the unfolded system's (xi != 0), none the model's, over an "
                                    "arclength of 30 of the scenario's largest steps"), b
            assert "physical_ranges" not in b and b["points"] >= 30, b
    if (k, beta) == (22.0, 0.33):
        # A stable stretch of walking next to the lift-off guards' boundary: from a located Neimark-Sacker
        # point to the located boundary (H = 1.00712 to 1.01159), both named in the ranges. On these symmetric
        # gaits the front leg's guard (a competing one: CB) and the rear leg's, the double support's own event
        # (touched inside the phase: GR), reach 0 at mirror times of the same orbit, so both are located
        # there, within their precision; the range names one of them.
        ends = {(r["from_how"].split(" #")[0], r["to_how"].split(" #")[0])
                for b in summary["branches"] for r in b.get("stable_ranges", [])}
        assert ("NS", "CB") in ends or ("NS", "GR") in ends, ends
        boundary = [sp for sp in summary["special_points"]
                    if sp["type"] in ("CB", "GR") and abs(sp["H"] - 1.0115911718) < 1e-8]
        assert {sp["type"] for sp in boundary} == {"CB", "GR"}, boundary


@pytest.fixture(scope="module")
def shipped(tmp_path_factory):
    out = tmp_path_factory.mktemp("shipped") / "run"
    return out, run_model(BIN, os.path.join(MODELS, "bipedal-slip.toml"), out)


def test_shipped_classifications_are_the_simulation_s(shipped):
    physical, refused = check_every_classification(Biped(K_GEYER, BETA_GEYER), *shipped)
    assert physical >= 10 and refused >= 5


def test_shipped_walking_at_820_joules_is_geyers_with_its_multipliers(shipped):
    out, summary = shipped
    biped = Biped(K_GEYER, BETA_GEYER)
    y = brentq(lambda y: biped.walking_step(H_820J, y)["end"][1] - y, 0.975, 0.985, xtol=1e-14)
    # The step map on the level H (mid-stance height and vertical speed), its multipliers by central
    # differences; the stride (two steps, the tool's word) has their squares.
    def step(v):
        e = biped.walking_step(H_820J, v[0], v[1])["end"]
        return np.array([e[1], e[3]])
    h = 1e-6
    J = np.column_stack([(step([y + h, 0]) - step([y - h, 0])) / (2 * h), (step([y, h]) - step([y, -h])) / (2 * h)])
    stride = sorted(np.linalg.eigvals(J) ** 2, key=lambda z: z.imag)
    start = [b for b in summary["branches"] if b.get("word") == ["stance", "double", "stance", "double"]][0]
    with open(out / start["file"]) as f:
        row = next(csv.DictReader(f))
    assert abs(float(row["H"]) - H_820J) < 1e-12
    assert abs(float(row["x1_y"]) - y) < 1e-8
    assert row["physical"] == "1"
    mu = sorted([complex(float(row["mu1_re"]), float(row["mu1_im"])), complex(float(row["mu2_re"]), float(row["mu2_im"]))],
                key=lambda z: z.imag)
    for a, b in zip(mu, stride):
        assert abs(a - b) < 1e-6, (mu, stride)
    # The family ends at a located grazing point below and a located constraint boundary (the lift-off guard
    # touched) above, and gains its stability at a located Neimark-Sacker point between them.
    points = {p["type"]: p for p in summary["special_points"]
              if p["branch"] in (0, 1) and p["status"] == "located" and p["type"] in ("GR", "CB", "NS")}
    assert set(points) == {"GR", "CB", "NS"}, points
    assert points["GR"]["H"] < 1.011 < 1.063 < points["NS"]["H"] < 1.064 < points["CB"]["H"] < 1.087
