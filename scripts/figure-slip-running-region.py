"""The region of self-stable spring-mass running in Seyfarth et al. (2002)'s axes and units, with a sweep of the
apex return map over the same plane drawn on it (docs/examples/slip-running.md).

    hybridcont run models/slip-running.toml --free k --fix H=2.28 --curves beta --out results/slip-running-plane
    /usr/bin/python3 scripts/figure-slip-running-region.py results/slip-running-plane docs/figures/slip-running-region.png

The curves and the region come from the results folder (summary.json's "curves" and "regions"); the dots are
tests/slip_running_reference.py's apex map (SciPy, Seyfarth et al.'s own method) on a grid of the plane: filled
where it finds stable running, open where running exists but is unstable, small grey where no running gait
exists. Units: m = 80 kg, l0 = 1 m, g = 9.81 m/s² (k [kN/m] = k · 80 · 9.81 / 1000; the angle of attack is
90° − beta). Prints the time of the curves (from summary.json) and of the sweep.
"""
import csv
import json
import os
import re
import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import slip_running_reference as reference  # noqa: E402

MASS, GRAVITY, LEG = 80.0, 9.81, 1.0
KN_PER_UNIT = MASS * GRAVITY / LEG / 1000.0  # dimensionless k -> kN/m


def attack_angle(beta):
    return 90.0 - np.degrees(beta)


def main(folder, figure):
    with open(os.path.join(folder, "summary.json")) as f:
        summary = json.load(f)
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    for region in summary.get("regions", []):
        if region["kind"] != "stable":
            continue
        p = np.array(region["polygon"])
        ax.fill(attack_angle(p[:, 0]), p[:, 1] * KN_PER_UNIT, color="#0072B2", alpha=0.25, lw=0,
                label="self-stable running (the curves' region)")
    styles = {"fold": ("#0072B2", ":", "fold: the stable and the unstable gait meet"),
              "period-doubling": ("#0072B2", "--", "period doubling: stability lost")}
    for c in summary["curves"]:
        if c["type"] not in styles:
            continue
        with open(os.path.join(folder, c["file"]), newline="") as f:
            rows = [(float(r["beta"]), float(r["k"])) for r in csv.DictReader(f)]
        b, k = np.array(sorted(rows)).T
        colour, dash, label = styles[c["type"]]
        ax.plot(attack_angle(b), k * KN_PER_UNIT, color=colour, ls=dash, lw=1.8, label=label)
    # The apex-map sweep over the plane.
    start = time.time()
    stable, unstable, none = [], [], []
    for beta in np.radians(90.0 - np.arange(58.0, 77.0, 1.5)):
        for k_kn in np.arange(6.0, 60.0, 3.0):
            c = reference.stable_running(k_kn / KN_PER_UNIT, beta, 2.28)
            (stable if c is True else unstable if c is False else none).append((attack_angle(beta), k_kn))
    sweep_seconds = time.time() - start
    for points, style in ((stable, dict(marker="o", color="#0072B2", ms=4, ls="", label="apex map: stable")),
                          (unstable, dict(marker="o", mfc="none", color="#D55E00", ms=4, ls="",
                                          label="apex map: unstable")),
                          (none, dict(marker=".", color="0.7", ms=3, ls="", label="apex map: no running gait"))):
        if points:
            x, y = np.array(points).T
            ax.plot(x, y, **style)
    ax.set_xlabel("angle of attack α₀ [deg]")
    ax.set_ylabel("leg stiffness k [kN/m]")
    ax.set_xlim(57, 77.5)
    ax.set_ylim(0, 62)
    ax.grid(True, color="0.9", lw=0.6)
    ax.set_title("Self-stable spring-mass running at E = %.0f J (m = 80 kg, l₀ = 1 m)"
                 % (2.28 * MASS * GRAVITY * LEG), fontsize=10)
    ax.legend(fontsize=7.5, loc="upper left", frameon=False)
    fig.tight_layout()
    fig.savefig(figure, dpi=150)
    wall = re.search(r"wall time ([0-9.]+) s", summary.get("report", ""))
    print("figure written to %s; the run with its curves %s s, the apex-map sweep (%d cells) %.1f s"
          % (figure, wall.group(1) if wall else "?", len(stable) + len(unstable) + len(none), sweep_seconds))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: figure-slip-running-region.py RESULTS_FOLDER FIGURE.png")
    main(sys.argv[1], sys.argv[2])
