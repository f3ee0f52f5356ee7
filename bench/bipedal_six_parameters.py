#!/usr/bin/env python3
"""Independent checks of `hybridcont run models/bipedal-slip.toml` at six (k, alpha0) of the bipedal
spring-mass model (units m = l0 = g = 1, beta = radians(90 - alpha0)), from their results folders.

For each folder <root>/k<K>_a<ALPHA0> (the tool run with --set k=K --set beta=repr(math.radians(90 - ALPHA0))):
  a. the level where symmetric running loses its flight, computed here (SciPy's DOP853, Brent's method):
     the stance from landing at (-sin b, cos b) with horizontal speed v and no vertical speed passes
     mid-stance with dy = 0; H = v^2/2 + cos b. v is bracketed by scanning a wide range for sign changes
     (every root is kept). Compared with the ZD points of the running word's branches where the flight
     vanishes (absolute difference against the tool's stated precision).
  b. every physical point (physical == 1) of every branch replayed from its section state x1 with the
     event-driven automaton of tests/automaton_reference.py (equations of tests/bipedal_slip_model.py):
     it must take the branch's word and return to x1 after the period t1 + ... + t5 (both to 1e-8; the
     state to 1e-8 * max(1, largest |mu|) as well, since an unstable orbit amplifies the file's own error).
  c. for the same points, the nontrivial Floquet multipliers: the Jacobian of the full-cycle return map
     (the whole word) on the section x = 0 restricted to the energy level, by central differences (step 1e-6,
     then / 10 until the largest |mu| settles to 1e-4 relative) in (y, dy) with dx fixed by the energy; stable when every |mu| <= 1 + 1e-6.
     Compared with the CSV's `stable` column and with the largest |mu| of its mu columns. Points whose largest
     |mu| (ours or the tool's) lies within 1e-4 of 1 are reported as marginal, not as agreement or not.
     The map here is the same automaton integrated by DOP853 at 1e-13 step by step, its guards sampled at most
     5e-4 apart on the dense output (a shallow crossing near a grazing is not missed) and flights in closed form;
     it must close the orbit itself before its differences are taken. It also replays the physical points
     automaton_reference cannot (a flight shorter than that replay's 1.25e-3 guard sampling) and the points the
     tool classified 'replay-failed' with every duration positive.
  d. prints per (k, alpha0): the families (physical H ranges from summary.json), the counts of a-c, the
     disagreements, and a verdict; then the total time.

Usage: /usr/bin/python3 bench/bipedal_six_parameters.py [ROOT ...]   (default /tmp/six; a (k, alpha0) is taken
from the first ROOT holding a complete k<K>_a<ALPHA0>/summary.json)
"""
import csv
import json
import math
import os
import sys
import time

import numpy as np
from scipy.integrate import DOP853, solve_ivp
from scipy.optimize import brentq

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))
from automaton_reference import replay  # noqa: E402
from bipedal_slip_model import Biped  # noqa: E402

SIX = [(12, 66), (20, 68), (20, 72), (30, 68), (30, 72), (40, 70)]
TRANSITION = {("stance", "double"): "touchdown", ("stance", "flight"): "liftoff",
              ("flight", "stance"): "landing", ("double", "stance"): "rear_off"}
FD_STEP, STABLE_TOL, MARGINAL, REPLAY_TOL = 1e-6, 1e-6, 1e-4, 1e-8
OPT = dict(method="DOP853", rtol=1e-13, atol=1e-13)


# ---------------------------------------------------------------- a. the zero-flight level of symmetric running

def zero_flight_levels(k, beta, rtol=1e-13):
    """Every level H = v^2/2 + cos b where the stance from landing at (-sin b, cos b) with velocity (v, 0)
    passes mid-stance (x = 0, before lift-off) with dy = 0; v bracketed by a scan of [0.05, 20]."""
    S, C = math.sin(beta), math.cos(beta)

    def rhs(t, s):
        x, y, dx, dy = s
        f = k * (1 / math.hypot(x, y) - 1)
        return [dx, dy, f * x, f * y - 1]

    def dy_mid(v, tol=rtol):
        mid = lambda t, s: s[0]
        mid.terminal, mid.direction = True, 1
        lo = lambda t, s: 1 - math.hypot(s[0], s[1])  # the leg back at rest length: lift-off first
        lo.terminal, lo.direction = True, -1
        sol = solve_ivp(rhs, [0, 50], [-S, C, v, 0.0], events=[mid, lo], method="DOP853", rtol=tol, atol=tol)
        if sol.t_events[0].size == 0 or (sol.t_events[1].size and sol.t_events[1][0] < sol.t_events[0][0]):
            return None
        return sol.y_events[0][0][3]

    vs = np.geomspace(0.05, 20, 240)
    values = [dy_mid(v, 1e-11) for v in vs]
    levels = []
    for a, b, fa, fb in zip(vs[:-1], vs[1:], values[:-1], values[1:]):
        if fa is None or fb is None or (fa > 0) == (fb > 0):
            continue
        v = brentq(dy_mid, a, b, xtol=1e-15, rtol=1e-15)
        v12 = brentq(lambda v: dy_mid(v, 1e-12), a, b, xtol=1e-15, rtol=1e-15)
        levels.append((0.5 * v * v + C, abs(0.5 * v * v - 0.5 * v12 * v12), v))
    return levels


# ------------------------------------------------------------------ b. and c. the orbits of the branch files

def transitions_of(word, name):
    """The transitions of a word of modes (its `words` name says which leg leaves `double`)."""
    parts = name.split(" > ") if name else []
    out = []
    for i, m in enumerate(word):
        nxt = word[(i + 1) % len(word)]
        t = TRANSITION[(m, nxt)]
        if i < len(parts) and "(" in parts[i]:
            t = parts[i].split("(")[1].rstrip(")").strip()
        out.append(t)
    return out


class ReturnMap:
    """The full-cycle map on the section x = 0 (stance) at level H: the automaton of tests/bipedal_slip_model.py
    (its guards, resets and the 'first guard crossed from above, once armed' rule of automaton_reference),
    integrated here by DOP853 at 1e-13 with the guards sampled finely on its dense output, flights in
    closed form: smoother and more accurate than automaton_reference's fixed grid, for differences."""

    def __init__(self, k, beta):
        self.k, self.S, self.C = k, math.sin(beta), math.cos(beta)
        self.biped = Biped(k, beta)

    def section_state(self, H, y, dy):
        V = y + 0.5 * self.k * (y - 1) ** 2
        q = 2 * (H - V) - dy * dy
        return None if q <= 0 else [0.0, y, math.sqrt(q), dy]

    @staticmethod
    def first_crossing(rhs, x0, watched, horizon=20.0, spacing=5e-4, arming=1e-12):
        """The first guard of `watched` crossed from above, (index, time, state) or None: DOP853 step by step,
        every guard sampled on its dense output at most `spacing` apart (a shallow dip below 0 inside one
        step, as near a grazing, is not missed), armed once it has been above `arming` (a guard a reset
        leaves on 0 is not taken at once), the crossing located by Brent's method on the dense output."""
        guards = [g for _, g, _, _ in watched]
        solver = DOP853(rhs, 0.0, np.asarray(x0, float), horizon, rtol=OPT["rtol"], atol=OPT["atol"])
        prev = [g(x0) for g in guards]
        armed = [v > arming for v in prev]
        while solver.status == "running":
            solver.step()
            if solver.status == "failed":
                return None
            dense = solver.dense_output()
            n = max(4, int(math.ceil((solver.t - solver.t_old) / spacing)))
            ts = np.linspace(solver.t_old, solver.t, n + 1)
            states = dense(ts[1:]).T
            for i, x in enumerate(states):
                cur = [g(x) for g in guards]
                hits = []
                for j, g in enumerate(guards):
                    if armed[j] and prev[j] > 0 and cur[j] <= 0:
                        t = brentq(lambda t: g(dense(t)), ts[i], ts[i + 1], xtol=1e-15, rtol=1e-15)
                        hits.append((t, j))
                    armed[j] = armed[j] or cur[j] > arming
                if hits:
                    t, j = min(hits)
                    return j, t, dense(t)
                prev = cur
        return None

    def run(self, x1, legs):
        """From x1 in stance: the transitions taken and the state at the anchor after `legs` of them."""
        modes, mode, x, taken = self.biped.modes, "stance", list(x1), []
        for leg in range(legs + 1):
            rhs, out = modes[mode]
            if mode == "flight" and leg < legs:
                # ballistic: y = y0 + dy t - t^2/2 crosses the landing height C from above (armed once it has
                # been above it by 1e-12); solved in closed form, as the integrator's steps in this polynomial
                # flow are so long that a short flight would go unseen between two of them
                y0, vx, vy = x
                if y0 - self.C <= 1e-12 and (vy <= 0 or y0 - self.C + vy * vy / 2 <= 1e-12):
                    return taken, None
                t = vy + math.sqrt(vy * vy + 2 * (y0 - self.C))
                name, _, target, reset = out[0]
                taken.append(name)
                mode, x = target, reset([self.C, vx, vy - t])
                continue
            watched = list(out) + ([self.biped.anchor] if leg == legs else [])
            hit = self.first_crossing(rhs, x, watched)
            if hit is None:
                return taken, None
            j, _, x_end = hit
            name, _, target, reset = watched[j]
            x_end = list(x_end)
            if name == "anchor":
                return taken, x_end
            taken.append(name)
            mode, x = target, reset(x_end)
        return taken, None

    def jacobian_eigenvalues(self, H, y, dy, transitions, h):
        """Eigenvalues of the 2x2 Jacobian of (y, dy) -> (y', dy') by central differences of step h; None if
        a perturbed orbit takes another word."""
        cols = []
        for dyy, ddy in ((h, 0.0), (0.0, h)):
            ends = []
            for s in (1, -1):
                x1 = self.section_state(H, y + s * dyy, dy + s * ddy)
                taken, end = self.run(x1, len(transitions)) if x1 else (None, None)
                if end is None or taken != transitions:
                    return None
                ends.append(np.array([end[1], end[3]]))
            cols.append((ends[0] - ends[1]) / (2 * h))
        return np.linalg.eigvals(np.column_stack(cols))

    def multipliers(self, H, y, dy, transitions):
        """The nontrivial multipliers: central differences from step FD_STEP down by factors of 10 until the
        largest |mu| changes by less than 1e-4 relative from one step to the next (the map is strongly
        nonlinear where a flight nearly vanishes); (eigenvalues, step) or (None, None)."""
        previous = None
        for e in range(6):
            h = FD_STEP / 10 ** e
            mu = self.jacobian_eigenvalues(H, y, dy, transitions, h)
            if mu is None:
                continue
            if previous is not None and abs(max(abs(mu)) - max(abs(previous))) <= 1e-4 * max(1.0, max(abs(mu))):
                return mu, h
            previous = mu
        return (previous, None) if previous is not None else (None, None)


def read_branch(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def check_folder(folder, k, alpha0):
    beta = math.radians(90 - alpha0)
    summary = json.load(open(os.path.join(folder, "summary.json")))
    assert abs(summary["parameters"]["beta"] - beta) < 1e-15 and summary["parameters"]["k"] == k
    rm = ReturnMap(k, beta)
    biped = rm.biped
    names = {tuple(w["word"]): w.get("name", "") for w in summary.get("words", [])}
    lines = [f"== k = {k}, alpha0 = {alpha0} deg (beta = {beta:.15g}), {folder}: status {summary.get('status')}, "
             f"exploration {summary.get('exploration', {}).get('status')}, {len(summary['branches'])} branches"]
    for f in summary.get("families", []):
        rng = ", ".join(f"{p['from']:.10g} ({p['from_end']}) .. {p['to']:.10g} ({p['to_end']})" for p in f["physical"])
        lines.append(f"  family {f['name']:8s} physical H {rng or 'none'}")
    if not summary.get("families"):
        lines.append("  no family")
    lines.append(f"  start note: {summary.get('start_note', '')}")

    # a.
    levels = zero_flight_levels(k, beta)
    lines.append("  a. zero-flight level(s) here: " + (", ".join(f"{h:.13f} (+-{e:.1e}, v = {v:.6f})"
                                                               for h, e, v in levels) or "none in v in [0.05, 20]"))
    run_word = ["stance", "flight", "stance", "flight"]
    run_branches = {b["id"]: b for b in summary["branches"] if b["word"] == run_word}
    zd_ok = zd_bad = 0
    zd_other = 0
    for p in summary["special_points"]:
        if p.get("type") != "ZD" or p["branch"] not in run_branches or "phase 'flight'" not in p.get("message", ""):
            continue
        nearest = min(levels, key=lambda l: abs(p["H"] - l[0]), default=(float("inf"), 0.0, None))
        d, prec = abs(p["H"] - nearest[0]), p.get("precision", float("nan"))
        b = run_branches[p["branch"]]
        ends = any(p["id"] == r.get("to_special_point") or p["id"] == r.get("from_special_point")
                   for r in b.get("physical_ranges", []))
        if d > 1e-6 and not ends:
            zd_other += 1  # a flight vanishing on some other (non-symmetric or non-physical) orbit
            continue
        good = d <= prec + nearest[1]  # the tool's stated precision plus our own error estimate
        zd_ok += good
        zd_bad += not good
        pr = [f"{r['from']:.6g}..{r['to']:.6g} ({r['to_how'].split(',')[0]})" for r in b.get("physical_ranges", [])]
        lines.append(f"     {p['label']} (branch {p['branch']}, {p['status']}, "
                     f"{'ends a physical range' if ends else 'ends no physical range: ' + ('; '.join(pr) or 'none')}): "
                     f"H = {p['H']:.13f}, |diff| = {d:.2e}, stated precision {prec:.1e} -> "
                     f"{'within' if good else 'OUTSIDE'}")
    if zd_other:
        lines.append(f"     ({zd_other} other flight-ZD points on running-word branches, not at a zero-flight level)")
    if zd_ok + zd_bad == 0:
        lines.append("     no ZD point of the running word at the zero-flight level")

    # b. and c.
    nb_ok = nb_bad = nb_scaled = nb_fallback = 0
    nc_ok = nc_bad = nc_marg = nc_fail = unconverged = 0
    worst_rel = (0.0, None)
    bad_lines, replay_failed = [], []
    for b in summary["branches"]:
        word = b["word"]
        trans = transitions_of(word, names.get(tuple(word), ""))
        m = len(word)
        for row in read_branch(os.path.join(folder, b["file"])):
            if row["physical"] != "1":
                if row.get("classification") == "replay-failed" and \
                        all(float(row[f"t{i}"]) > 0 for i in range(1, m + 2)):
                    # the tool could not replay this orbit; does the event map here close it?
                    x1 = [float(row[f"x1_{s}"]) for s in ("x", "y", "dx", "dy")]
                    taken_here, end_here = rm.run(x1, m)
                    gap = max(abs(a - c) for a, c in zip(end_here, x1)) if end_here else float("inf")
                    flight = min((float(row[f"t{i + 1}"]) for i, md in enumerate(word) if md == "flight"),
                                 default=float("nan"))
                    replay_failed.append(f"     tool 'replay-failed': branch {b['id']} index {row['index']} H = "
                                         f"{float(row['H']):.10g} (shortest flight {flight:.2e}): here it takes "
                                         f"{'its word' if taken_here == trans else taken_here} and closes to {gap:.1e}")
                continue
            H = float(row["H"])
            x1 = [float(row[f"x1_{s}"]) for s in ("x", "y", "dx", "dy")]
            period = sum(float(row[f"t{i}"]) for i in range(1, m + 2))
            mus = [complex(float(row[f"mu{i}_re"]), float(row[f"mu{i}_im"]))
                   for i in (1, 2) if row.get(f"mu{i}_re") not in (None, "")]
            theirs_max = max(abs(u) for u in mus)
            # b.
            try:
                taken, t, x_end = replay(biped.modes, biped.anchor, "stance", x1, m)
                how = ""
            except AssertionError:
                # no guard crossed: automaton_reference arms a guard only once it has been above 1e-8, so a
                # flight whose apex is less than 1e-8 above the landing height cannot land there; replay such
                # an orbit with the event map here (armed above 1e-12) instead, and say so
                flight = min((float(row[f"t{i + 1}"]) for i, mode in enumerate(word) if mode == "flight"),
                             default=float("nan"))
                taken, x_end = rm.run(x1, m)
                t, how = period, (f" (automaton_reference found no guard: flight {flight:.1e} shorter than its"
                                  " guard sampling step 1.25e-3; replayed with the event map here, state only)")
                nb_fallback += 1
                if x_end is None:
                    x_end = [float("inf")] * 4
            err_t, err_x = abs(t - period), float(np.max(np.abs(np.array(x_end) - np.array(x1))))
            if how:
                bad_lines.append(f"     b. branch {b['id']} index {row['index']} H = {H:.10g}{how}: took {taken}, "
                                 f"|dx| = {err_x:.1e}")
            if taken == trans and err_t < REPLAY_TOL * max(1, period) and err_x < REPLAY_TOL:
                nb_ok += 1
            elif taken == trans and err_t < REPLAY_TOL * max(1, period) * max(1, theirs_max) \
                    and err_x < REPLAY_TOL * max(1, theirs_max):
                nb_scaled += 1
            else:
                nb_bad += 1
                bad_lines.append(f"     b. branch {b['id']} index {row['index']} H = {H:.10g}: took {taken}, "
                                 f"|dt| = {err_t:.1e}, |dx| = {err_x:.1e} (|mu| max {theirs_max:.3g})")
            # c. (the event map here must close the orbit too, or its differences are of another orbit)
            taken_here, end_here = rm.run(x1, m)
            if taken_here != trans or end_here is None or \
                    max(abs(a - b) for a, b in zip(end_here, x1)) > 1e-6 * max(1.0, theirs_max):
                nc_fail += 1
                bad_lines.append(f"     c. branch {b['id']} index {row['index']} H = {H:.10g}: the event map here does "
                                 f"not close the orbit (took {taken_here}, end {end_here})")
                continue
            ours, h = rm.multipliers(H, x1[1], x1[3], trans)
            if ours is not None and h is None:
                unconverged += 1
            if ours is None:
                nc_fail += 1
                bad_lines.append(f"     c. branch {b['id']} index {row['index']} H = {H:.10g}: the word changes "
                                 "under every finite-difference step tried")
                continue
            ours_max = float(max(abs(ours)))
            rel = abs(ours_max - theirs_max) / max(1.0, theirs_max)
            if rel > worst_rel[0]:
                worst_rel = (rel, (b["id"], row["index"], H, ours_max, theirs_max))
            our_stable = ours_max <= 1 + STABLE_TOL
            their_stable = row["stable"] in ("1", "1.0")
            if abs(ours_max - 1) < MARGINAL or abs(theirs_max - 1) < MARGINAL:
                nc_marg += 1
                bad_lines.append(f"     c. marginal: branch {b['id']} index {row['index']} H = {H:.10g}: "
                                 f"|mu| max ours {ours_max:.8f}, theirs {theirs_max:.8f}, stable column {row['stable']}")
            elif our_stable == their_stable:
                nc_ok += 1
            else:
                nc_bad += 1
                bad_lines.append(f"     c. DISAGREE branch {b['id']} index {row['index']} H = {H:.10g}: ours "
                                 f"{'stable' if our_stable else 'unstable'} (|mu| max {ours_max:.8g}), theirs "
                                 f"stable={row['stable']} (|mu| max {theirs_max:.8g})")
    n = nb_ok + nb_bad + nb_scaled
    lines.append(f"  b. replay of {n} physical points (every one): {nb_ok} agree to 1e-8, "
                 f"{nb_scaled} only to 1e-8*|mu|max, {nb_bad} disagree ({nb_fallback} replayed with the event map, see below)")
    lines.append(f"  c. stability: {nc_ok} agree, {nc_bad} disagree, {nc_marg} marginal, {nc_fail} not computed; "
                 "largest relative |mu|max difference " +
                 (f"{worst_rel[0]:.1e} (branch {worst_rel[1][0]} index {worst_rel[1][1]}, H = {worst_rel[1][2]:.6g}, "
                  f"ours {worst_rel[1][3]:.8g}, theirs {worst_rel[1][4]:.8g})" if worst_rel[1] else "-"))
    lines += bad_lines + replay_failed
    verdict = "AGREE" if zd_bad == 0 and nb_bad == 0 and nc_bad == 0 else "DISAGREE"
    lines.append(f"  verdict: {verdict} (ZD {zd_ok} within / {zd_bad} outside the stated precision; replay {nb_bad} "
                 f"bad; stability {nc_bad} bad, {nc_marg} marginal, {nc_fail} not computed)")
    return lines


def main():
    roots = sys.argv[1:] or ["/tmp/six"]
    t0 = time.time()
    for k, a in SIX:
        found = [os.path.join(r, f"k{k}_a{a}") for r in roots
                 if os.path.exists(os.path.join(r, f"k{k}_a{a}", "summary.json"))]
        if not found:
            print(f"== k = {k}, alpha0 = {a}: no results (summary.json) under {', '.join(roots)}")
            continue
        folder = found[0]
        t = time.time()
        print("\n".join(check_folder(folder, k, a)) + f"\n  ({time.time() - t:.0f} s)", flush=True)
    print(f"total time {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
