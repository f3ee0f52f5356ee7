#!/usr/bin/env python3
"""Figures for the results of ``hybridcont run`` (paper §4: Figs. HoverT, bouncingrod, rodKeyFrame, slip,
slipKeyFrame, ballrockFrame).

Usage::

    /usr/bin/python3 hybridcont_plot.py RESULTS_DIR [--svg] [--frames N]

Reads RESULTS_DIR/summary.json and the CSV files it names, writes the figures into RESULTS_DIR as PNG
(150 dpi; with ``--svg`` also as SVG) and prints the paths of the files written, one per line.
Exits with status 2 and a one-line message on stderr when the folder or summary.json is missing or
malformed, with status 1 when some figure could not be drawn (the others are still written).
Only the standard library and matplotlib (Agg backend) are used.

Data contract (fields are looked up by name; unknown fields and columns are ignored)
-----------------------------------------------------------------------------------
summary.json
    model           "bouncing-ball" | "rocking-block" | "bouncing-rod" | "slip" | any other name
    parameters      {name: value}; used: l0 (length scale, default 1), beta (block slenderness, default 0.3)
    phases          [{"name": str, "states": [str, ...]}, ...]; m = number of phases
    unknowns        names of the components of u (used to read special points' "u")
    branches        [{"id", "file", "parent" (special point id or -1), "points", "termination", "direction"}]
    special_points  [{"id", "type" (SB|TP|BP|PD|start|...), "branch", "index", "H", "T",
                      "status" (located|bracketed), "precision", "u"}]
    orbits          [{"file", "branch", "index", "H", "T", "label"}]   (optional)
branch-<id>.csv
    header row, then one row per point.  Used columns: H, T, xi (or xi1), t1..t<m+1>, x<i>_<state>, physical (1/0),
    classification (word), index (to find special points without "u"), stable (1/0/empty, optional).
    Segment i = 1..m+1 uses phase (i-1) mod m.  Empty or non-numeric cells are read as NaN.
orbit-<k>.csv
    columns t, segment, "<phase>.<state>" ...; each row fills only the columns of its segment's phase;
    t runs from 0 to T over one period.

Figures
-------
H_T.png          H-bar over T for every branch (Fig. HoverT / slip a).  Physical points (physical == 1)
                 solid, the rest dashed; a branch is split into runs of equal flag that share their
                 boundary point, so the line stays continuous.  One colour per branch.  Special points:
                 SB filled dot, TP open circle, BP square, PD diamond, start star; points only bracketed
                 (not located) have a grey edge.  With a "stable" column, stable physical parts are thicker.
                 A branch whose projection collapses to one point is drawn as a marker.
H_T_xi.png       (only when some xi != 0) the same in three dimensions T, xi, H-bar, showing the
                 branches that differ only in xi (e.g. the ball at rest).
slip_durations.png  (slip) stance durations t1 (lines) and t3 (open markers) over flight time t2 (Fig. slip b).
slip_speed.png   (slip) period T and forward speed dx in flight over H-bar (Fig. slip a).
rod_t2.png       (bouncing-rod) H-bar over t2, and the asymmetry t2 - (t1 + t3) over T (Fig. bouncingrod b).
rod_zoom.png     (bouncing-rod, if special points exist) H-bar over T around the special points
                 (Fig. bouncingrod a).
keyframes.png    key frames of up to 6 orbits of summary["orbits"] (one row each, equally spaced instants
                 from t = 0 to T, placed left to right), drawing the ball, the block, the rod or the hopper
                 (Figs. ballrockFrame, rodKeyFrame, slipKeyFrame).  The hopper's horizontal position is
                 reconstructed from its velocity (trapezoidal rule) with the foot fixed during stance.
"""

import argparse
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Circle, Polygon  # noqa: E402


class PlotError(Exception):
    """Fatal problem with the results folder (reported as one line, exit status 2)."""


# ----------------------------------------------------------------------------------------------------
# reading
# ----------------------------------------------------------------------------------------------------

def to_float(text):
    """Number in a CSV cell or JSON field, NaN when empty or not a number."""
    if text is None or isinstance(text, bool):
        return math.nan
    if isinstance(text, (int, float)):
        return float(text)
    try:
        return float(str(text).strip())
    except ValueError:
        return math.nan


def to_flag(text):
    """1/0 flag ("1", "1.0", "true", "yes" -> 1; "0", "false", "no" -> 0; anything else NaN)."""
    word = str(text).strip().lower()
    if word in ("true", "yes", "y", "t"):
        return 1.0
    if word in ("false", "no", "n", "f"):
        return 0.0
    v = to_float(text)
    return (1.0 if v == 1 else 0.0) if finite(v) else math.nan


def finite(*values):
    return all(isinstance(v, (int, float)) and math.isfinite(v) for v in values)


class Table:
    """A CSV file with a header row; columns are looked up by name."""

    def __init__(self, path):
        with open(path, newline="") as f:
            rows = [r for r in csv.reader(f) if r and any(c.strip() for c in r)]
        if not rows:
            raise ValueError("empty file (no header)")
        self.columns = [c.strip() for c in rows[0]]
        self.rows = rows[1:]
        self.n = len(self.rows)
        self._cache = {}

    def has(self, name):
        return name in self.columns

    def text(self, name):
        if name not in self.columns:
            return None
        j = self.columns.index(name)
        return [r[j].strip() if j < len(r) else "" for r in self.rows]

    def num(self, name):
        """Column as floats (NaN for empty cells), or None when the column does not exist."""
        if name not in self._cache:
            col = self.text(name)
            convert = to_flag if name in ("physical", "stable") else to_float
            self._cache[name] = None if col is None else [convert(c) for c in col]
        return self._cache[name]


def warn(message):
    print("hybridcont_plot: warning: " + message, file=sys.stderr)


def load_summary(results_dir):
    if not os.path.exists(results_dir):
        raise PlotError("results folder '%s' does not exist" % results_dir)
    if not os.path.isdir(results_dir):
        raise PlotError("'%s' is not a folder" % results_dir)
    path = os.path.join(results_dir, "summary.json")
    if not os.path.isfile(path):
        raise PlotError("no summary.json in '%s' (run 'hybridcont run MODEL --out DIR' first)" % results_dir)
    try:
        with open(path) as f:
            summary = json.load(f)
    except (OSError, ValueError) as e:
        raise PlotError("cannot read %s: %s" % (path, str(e).splitlines()[0]))
    if not isinstance(summary, dict):
        raise PlotError("%s is malformed: expected a JSON object" % path)
    for key in ("branches", "special_points", "orbits", "phases", "unknowns"):
        if key in summary and summary[key] is not None and not isinstance(summary[key], list):
            raise PlotError("%s is malformed: '%s' must be a list" % (path, key))
    if "branches" not in summary:
        raise PlotError("%s is malformed: no 'branches' list" % path)
    for key in ("branches", "special_points", "orbits"):
        items = summary.get(key) or []
        if not all(isinstance(b, dict) for b in items):
            raise PlotError("%s is malformed: entries of '%s' must be objects" % (path, key))
    if not isinstance(summary.get("parameters", {}) or {}, dict):
        raise PlotError("%s is malformed: 'parameters' must be an object" % path)
    return summary


def phases_of(summary):
    phases = []
    for p in summary.get("phases") or []:
        if isinstance(p, dict) and isinstance(p.get("name"), str):
            states = [s for s in (p.get("states") or []) if isinstance(s, str)]
            phases.append({"name": p["name"], "states": states})
    return phases


def load_branches(results_dir, summary):
    """List of dicts: id, entry (summary), table (Table or None)."""
    out = []
    for k, entry in enumerate(summary.get("branches") or []):
        bid = entry.get("id", k)
        fname = entry.get("file") or "branch-%s.csv" % bid
        path = os.path.join(results_dir, fname)
        table = None
        if os.path.isfile(path):
            try:
                table = Table(path)
            except (OSError, ValueError, csv.Error) as e:
                warn("skipping %s: %s" % (fname, e))
        else:
            warn("branch file %s is missing" % fname)
        if table is not None and (table.num("H") is None or table.num("T") is None):
            warn("skipping %s: no H or T column" % fname)
            table = None
        out.append({"id": bid, "entry": entry, "table": table})
    return out


# ----------------------------------------------------------------------------------------------------
# styling helpers
# ----------------------------------------------------------------------------------------------------

def branch_colour(position):
    cycle = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
             "#bcbd22", "#17becf"]
    return cycle[position % len(cycle)]


def axis_label(name):
    labels = {
        "H": r"energy $\bar{H}\ \ [m_\mathrm{o} g\, l_\mathrm{o}]$",
        "T": r"period $T\ \ [\sqrt{l_\mathrm{o}/g}]$",
        "xi": r"$\xi$",
        "speed": r"forward speed $\dot{x}$ in flight $[\sqrt{g\, l_\mathrm{o}}]$",
        "asym": r"$t_2-(t_1+t_3)\ \ [\sqrt{l_\mathrm{o}/g}]$",
    }
    if name in labels:
        return labels[name]
    if name.startswith("t") and name[1:].isdigit():
        return r"$t_{%s}\ \ [\sqrt{l_\mathrm{o}/g}]$" % name[1:]
    return name


def special_point_style(kind, bracketed):
    styles = {
        "SB": dict(marker="o", s=42, facecolor="black", edgecolor="black", name="SB simple bifurcation"),
        "TP": dict(marker="o", s=46, facecolor="white", edgecolor="black", name="TP turning point"),
        "BP": dict(marker="s", s=40, facecolor="black", edgecolor="black", name="BP branch point"),
        "PD": dict(marker="D", s=38, facecolor="#d62728", edgecolor="black", name="PD period doubling"),
        "start": dict(marker="*", s=120, facecolor="gold", edgecolor="black", name="start point"),
    }
    style = dict(styles.get(kind, dict(marker="X", s=46, facecolor="#9467bd", edgecolor="black",
                                       name=str(kind))))
    style["linewidth"] = 1.0
    if bracketed:
        style["edgecolor"] = "0.55"
        style["linewidth"] = 2.0
        if style["facecolor"] == "black":
            style["facecolor"] = "0.35"
        style["name"] = style["name"].split(" ")[0] + ", bracketed only"
    return style


def branch_label(branch, special_points):
    entry = branch["entry"]
    label = "branch %s" % branch["id"]
    parent = entry.get("parent", -1)
    if isinstance(parent, (int, float)) and not isinstance(parent, bool) and parent >= 0:
        kind = "SP"
        for sp in special_points:
            if sp.get("id") == parent:
                kind = sp.get("type", "SP")
        label += " (from %s %d)" % (kind, int(parent))
    table = branch["table"]
    if table is not None and table.n > 0:
        phys = table.num("physical")
        classes = table.text("classification")
        if phys is not None and not any(p == 1 for p in phys) and classes:
            counts = {}
            for c in classes:
                if c and c != "physical":
                    counts[c] = counts.get(c, 0) + 1
            if counts:
                label += ", " + max(counts, key=counts.get)
    elif table is not None:
        label += ", no points"
    return label


def plot_runs(ax, xs, ys, phys, stable, colour, zs=None):
    """Draw one branch: runs of equal (physical, stable) flag, solid/dashed, sharing boundary points.

    Points with a non-finite coordinate break the line.  Returns True when something was drawn."""
    n = len(xs)
    pts = []
    for i in range(n):
        coords = (xs[i], ys[i]) if zs is None else (xs[i], ys[i], zs[i])
        pts.append(coords if finite(*coords) else None)
    good = [p for p in pts if p is not None]
    if not good:
        return False

    def key(i):
        p = 1 if (phys is not None and phys[i] == 1) else 0
        s = 1 if (p and stable is not None and stable[i] == 1) else 0
        return (p, s)

    def draw(run, k):
        lw = 2.9 if k[1] else (1.8 if k[0] else 1.4)
        ls = "-" if k[0] else (0, (4.0, 2.5))
        cols = list(zip(*run))
        ax.plot(*cols, color=colour, lw=lw, ls=ls, solid_capstyle="round", zorder=2 + k[0])

    span = max(max(abs(c[d] - good[0][d]) for c in good) for d in range(len(good[0])))
    scale = max(1.0, max(abs(v) for c in good for v in c))
    if span <= 1e-12 * scale:  # projection collapses to a point
        k = key(next(i for i in range(n) if pts[i] is not None))
        ax.plot(*[[v] for v in good[0]], marker="o", ms=7, color=colour,
                mfc=colour if k[0] else "white", mew=1.6, ls="none", zorder=4)
        return "point"

    run, run_key = [], None
    for i in range(n):
        if pts[i] is None:
            if len(run) >= 2:
                draw(run, run_key)
            elif len(run) == 1:
                ax.plot(*[[v] for v in run[0]], marker=".", color=colour, ls="none")
            run, run_key = [], None
            continue
        k = key(i)
        if run_key is None:
            run, run_key = [pts[i]], k
        elif k == run_key:
            run.append(pts[i])
        else:
            # the segment across the switch belongs to the new run; the boundary point is shared
            if len(run) >= 2:
                draw(run, run_key)
            run, run_key = [run[-1], pts[i]], k
    if len(run) >= 2:
        draw(run, run_key)
    elif len(run) == 1:
        k = run_key
        ax.plot(*[[v] for v in run[0]], marker="o", ms=5, color=colour, mfc=colour if k[0] else "white",
                ls="none", zorder=4)
    return True


class Results:
    """Everything read from a results folder."""

    def __init__(self, results_dir):
        self.dir = results_dir
        self.summary = load_summary(results_dir)
        self.model = str(self.summary.get("model") or "unknown")
        self.parameters = {k: to_float(v) for k, v in (self.summary.get("parameters") or {}).items()}
        self.phases = phases_of(self.summary)
        self.m = len(self.phases)
        self.unknowns = [u for u in (self.summary.get("unknowns") or []) if isinstance(u, str)]
        self.special_points = [sp for sp in (self.summary.get("special_points") or []) if isinstance(sp, dict)]
        self.branches = load_branches(results_dir, self.summary)
        for pos, b in enumerate(self.branches):
            b["colour"] = branch_colour(pos)
            b["label"] = branch_label(b, self.special_points)
        self.by_id = {b["id"]: b for b in self.branches}

    def parameter(self, name, default):
        v = self.parameters.get(name, math.nan)
        return v if finite(v) else default

    def has_stable(self):
        return any(b["table"] is not None and b["table"].num("stable") is not None
                   and any(s == 1 for s in b["table"].num("stable")) for b in self.branches)

    def column(self, branch, name):
        """Branch column by name; "asym" = t2 - (t1 + t3); None when absent."""
        t = branch["table"]
        if t is None:
            return None
        if name == "asym":
            t1, t2, t3 = t.num("t1"), t.num("t2"), t.num("t3")
            if t1 is None or t2 is None or t3 is None:
                return None
            return [b - (a + c) for a, b, c in zip(t1, t2, t3)]
        if name == "xi" and not t.has("xi") and t.has("xi1"):  # several first integrals: xi1..xik
            return t.num("xi1")
        return t.num(name)

    def sp_value(self, sp, name):
        """Coordinate `name` of a special point: from its own field, from "u", or from its branch row."""
        if name in ("H", "T") and finite(to_float(sp.get(name))):
            return to_float(sp.get(name))
        u = sp.get("u")
        if name == "asym":
            vals = [self.sp_value(sp, c) for c in ("t1", "t2", "t3")]
            return vals[1] - (vals[0] + vals[2]) if finite(*vals) else math.nan
        key = "xi1" if name == "xi" and "xi" not in self.unknowns else name
        if isinstance(u, list) and len(u) == len(self.unknowns) and key in self.unknowns:
            v = to_float(u[self.unknowns.index(key)])
            if finite(v):
                return v
        if name == "T" and isinstance(u, list) and len(u) == len(self.unknowns):
            ts = [to_float(u[i]) for i, n in enumerate(self.unknowns) if n.startswith("t") and n[1:].isdigit()]
            if ts and finite(*ts):
                return sum(ts)
        branch = self.by_id.get(sp.get("branch"))
        if branch is None or branch["table"] is None:
            return math.nan
        col = self.column(branch, name)
        index = sp.get("index")
        if col is None or not isinstance(index, (int, float)):
            return math.nan
        idx_col = branch["table"].num("index")
        row = None
        if idx_col is not None:
            for r, v in enumerate(idx_col):
                if v == index:
                    row = r
                    break
        if row is None and 0 <= int(index) < len(col):
            row = int(index)
        return col[row] if row is not None else math.nan


# ----------------------------------------------------------------------------------------------------
# bifurcation diagrams
# ----------------------------------------------------------------------------------------------------

def draw_special_points(ax, res, xname, yname, zname=None, annotate=True, only=None):
    """Markers of the special points; returns {legend name: style} of those drawn."""
    used = {}
    for sp in res.special_points:
        kind = str(sp.get("type", "?"))
        if only is not None and not only(sp):
            continue
        x, y = res.sp_value(sp, xname), res.sp_value(sp, yname)
        z = res.sp_value(sp, zname) if zname else 0.0
        if not finite(x, y, z):
            continue
        style = special_point_style(kind, str(sp.get("status", "located")) != "located")
        kw = dict(marker=style["marker"], s=style["s"], facecolors=style["facecolor"],
                  edgecolors=style["edgecolor"], linewidths=style["linewidth"], zorder=6)
        if zname:
            ax.scatter([x], [y], [z], depthshade=False, **kw)
        else:
            ax.scatter([x], [y], **kw)
            if annotate and kind != "start":
                ax.annotate("%s%s" % (kind, sp.get("id", "")), (x, y), xytext=(5, 4),
                            textcoords="offset points", fontsize=7, color="0.2", zorder=7,
                            bbox=dict(boxstyle="round,pad=0.1", fc="white", ec="none", alpha=0.75))
        used[style["name"]] = style
    return used


def legend_handles(res, branches_drawn, sp_styles, stable=False, extra=()):
    handles = [Line2D([], [], color=b["colour"], lw=2, label=b["label"]) for b in branches_drawn]
    handles.append(Line2D([], [], color="0.2", lw=1.8, label="physical (solid)"))
    handles.append(Line2D([], [], color="0.2", lw=1.4, ls=(0, (4.0, 2.5)), label="non-physical (dashed)"))
    if stable:
        handles.append(Line2D([], [], color="0.2", lw=2.9, label="stable (thick)"))
    handles.extend(extra)
    for name in sorted(sp_styles):
        st = sp_styles[name]
        handles.append(Line2D([], [], marker=st["marker"], ls="none", ms=math.sqrt(st["s"]) * 1.05,
                              mfc=st["facecolor"], mec=st["edgecolor"], mew=st["linewidth"], label=name))
    return handles


def place_legend(fig, ax, handles):
    ncol = 1 if len(handles) <= 16 else 2
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False,
              ncol=ncol, borderaxespad=0.0, handlelength=2.6)


def projection(ax, res, xname, yname, sp=True, annotate=True, sp_filter=None):
    """Draw all branches in the (xname, yname) projection; returns (branches drawn, special point styles)."""
    stable = res.has_stable()
    drawn = []
    for b in res.branches:
        xs, ys = res.column(b, xname), res.column(b, yname)
        if xs is None or ys is None:
            continue
        t = b["table"]
        st = t.num("stable") if stable else None
        how = plot_runs(ax, xs, ys, t.num("physical"), st, b["colour"])
        if how:
            drawn.append(dict(b, label=b["label"] + ("; a point here" if how == "point" else "")))
    sp_styles = draw_special_points(ax, res, xname, yname, annotate=annotate, only=sp_filter) if sp else {}
    ax.set_xlabel(axis_label(xname))
    ax.set_ylabel(axis_label(yname))
    ax.grid(True, color="0.9", lw=0.6)
    return drawn, sp_styles


def model_title(res):
    names = {"bouncing-ball": "bouncing ball", "rocking-block": "rocking block", "bouncing-rod": "bouncing rod",
             "slip": "SLIP hopper"}
    title = names.get(res.model, res.model)
    pars = ", ".join("%s=%g" % (k, v) for k, v in sorted(res.parameters.items()) if finite(v))
    return title + (" (%s)" % pars if pars else "")


def save(fig, res, name, svg, written):
    path = os.path.join(res.dir, name + ".png")
    fig.savefig(path, dpi=150, bbox_inches="tight")
    written.append(path)
    if svg:
        path = os.path.join(res.dir, name + ".svg")
        fig.savefig(path, bbox_inches="tight")
        written.append(path)
    plt.close(fig)


def figure_h_t(res, svg, written):
    fig, ax = plt.subplots(figsize=(7.0, 4.8))
    drawn, sp_styles = projection(ax, res, "T", "H")
    extra = []
    if res.model == "rocking-block":  # energy bound of the homoclinic orbit (paper Fig. HoverT b)
        h_max = res.parameter("m", 1.0) * res.parameter("g", 1.0) * res.parameter("l0", 1.0) * (
            1.0 - math.cos(res.parameter("beta", 0.3)))
        ax.axhline(h_max, color="0.45", lw=0.9, ls=":", zorder=1)
        extra.append(Line2D([], [], color="0.45", lw=0.9, ls=":",
                            label=r"$\bar{H}_\mathrm{max}=m_\mathrm{o} g l_\mathrm{o}(1-\cos\beta)$"))
    if not drawn:
        ax.text(0.5, 0.5, "no branch points", transform=ax.transAxes, ha="center", va="center", color="0.4")
    ax.set_title(r"$\bar{H}$ over $T$: " + model_title(res), fontsize=10)
    place_legend(fig, ax, legend_handles(res, drawn, sp_styles, res.has_stable(), extra))
    save(fig, res, "H_T", svg, written)


def has_nonzero_xi(res):
    for b in res.branches:
        xi = res.column(b, "xi")
        if xi and any(finite(v) and abs(v) > 1e-9 for v in xi):
            return True
    return False


def figure_h_t_xi(res, svg, written):
    fig = plt.figure(figsize=(7.6, 5.4))
    ax = fig.add_subplot(111, projection="3d")
    drawn = []
    stable = res.has_stable()
    for b in res.branches:
        xs, ys, zs = res.column(b, "T"), res.column(b, "xi"), res.column(b, "H")
        if xs is None or ys is None or zs is None:
            continue
        t = b["table"]
        how = plot_runs(ax, xs, ys, t.num("physical"), t.num("stable") if stable else None, b["colour"], zs=zs)
        if how:
            drawn.append(dict(b, label=b["label"] + ("; a point here" if how == "point" else "")))
    sp_styles = draw_special_points(ax, res, "T", "xi", zname="H")
    ax.set_xlabel(axis_label("T"), fontsize=8)
    ax.set_ylabel(axis_label("xi"), fontsize=8)
    ax.set_zlabel(axis_label("H"), fontsize=8)
    ax.tick_params(labelsize=7)
    ax.view_init(elev=22, azim=-60)
    ax.set_title(r"$\bar{H}$ over $T$ and $\xi$: " + model_title(res), fontsize=10)
    handles = legend_handles(res, drawn, sp_styles, stable)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.08, 1.0), fontsize=8, frameon=False)
    save(fig, res, "H_T_xi", svg, written)


def flight_speed_column(res):
    """x<i>_dx of the first segment whose phase has a state "dx" (x2_dx for the SLIP)."""
    for i in range(1, res.m + 2):
        if "dx" in res.phases[(i - 1) % res.m]["states"]:
            return "x%d_dx" % i
    return "x2_dx"


def figure_slip_durations(res, svg, written):
    fig, ax = plt.subplots(figsize=(7.0, 4.8))
    drawn, sp_styles = projection(ax, res, "t2", "t1", annotate=True)
    stable = res.has_stable()
    for b in res.branches:
        xs, ys = res.column(b, "t2"), res.column(b, "t3")
        if xs is None or ys is None:
            continue
        t = b["table"]
        plot_runs(ax, xs, ys, t.num("physical"), t.num("stable") if stable else None, b["colour"])
        pts = [(x, y) for x, y in zip(xs, ys) if finite(x, y)]
        every = max(1, len(pts) // 12)
        if pts:
            ax.plot(*zip(*pts[::every]), ls="none", marker="o", ms=4.5, mfc="white", mec=b["colour"], mew=1.1,
                    zorder=4)
    draw_special_points(ax, res, "t2", "t3", annotate=False)
    ax.set_ylabel(r"stance durations $t_1$, $t_3\ \ [\sqrt{l_\mathrm{o}/g}]$")
    ax.set_xlabel(r"flight time $t_2\ \ [\sqrt{l_\mathrm{o}/g}]$")
    ax.axvline(0.0, color="0.6", lw=0.8, zorder=1)
    ax.set_title(r"stance durations over flight time: " + model_title(res), fontsize=10)
    extra = [Line2D([], [], color="0.2", lw=1.8, label=r"$t_1$ (line)"),
             Line2D([], [], color="0.2", lw=1.8, marker="o", mfc="white", ms=4.5, label=r"$t_3$ (open markers)")]
    place_legend(fig, ax, legend_handles(res, drawn, sp_styles, stable, extra))
    save(fig, res, "slip_durations", svg, written)


def figure_slip_speed(res, svg, written):
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7.0, 6.4), sharex=True)
    drawn, sp_styles = projection(ax1, res, "H", "T")
    dx = flight_speed_column(res)
    projection(ax2, res, "H", dx)
    ax1.set_xlabel("")
    ax2.set_ylabel(axis_label("speed"))
    ax2.axhline(0.0, color="0.6", lw=0.8, zorder=1)
    ax1.set_title(r"period and forward speed over $\bar{H}$: " + model_title(res), fontsize=10)
    # layout first: an outside legend placed before tight_layout squeezes the axes (savefig's
    # bbox_inches="tight" keeps the legend in the image)
    fig.tight_layout()
    place_legend(fig, ax1, legend_handles(res, drawn, sp_styles, res.has_stable()))
    save(fig, res, "slip_speed", svg, written)


def figure_rod_t2(res, svg, written):
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10.5, 4.4))
    drawn, sp_styles = projection(ax1, res, "t2", "H")
    projection(ax2, res, "T", "asym")
    ax2.axhline(0.0, color="0.6", lw=0.8, zorder=1)
    ax1.set_xlabel(r"second flight time $t_2\ \ [\sqrt{l_\mathrm{o}/g}]$")
    ax1.set_title(r"(a) $\bar{H}$ over $t_2$", fontsize=10)
    ax2.set_title(r"(b) asymmetry $t_2-(t_1+t_3)$ over $T$ (0: symmetric orbits)", fontsize=10)
    fig.suptitle(model_title(res), fontsize=10)
    # layout first: an outside legend placed before tight_layout squeezes the axes (savefig's
    # bbox_inches="tight" keeps the legend in the image)
    fig.tight_layout()
    place_legend(fig, ax2, legend_handles(res, drawn, sp_styles, res.has_stable()))
    save(fig, res, "rod_t2", svg, written)


def data_range(res, name):
    vals = []
    for b in res.branches:
        col = res.column(b, name)
        if col:
            vals.extend(v for v in col if finite(v))
    return (min(vals), max(vals)) if vals else (0.0, 1.0)


def figure_rod_zoom(res, svg, written):
    interesting = [sp for sp in res.special_points if sp.get("type") != "start"
                   and finite(res.sp_value(sp, "T"), res.sp_value(sp, "H"))]
    if not interesting:
        return
    ids = set(id(sp) for sp in interesting)
    fig, ax = plt.subplots(figsize=(7.0, 4.8))
    drawn, sp_styles = projection(ax, res, "T", "H", sp_filter=lambda sp: id(sp) in ids)
    limits = []
    for name in ("T", "H"):
        vals = [res.sp_value(sp, name) for sp in interesting]
        lo, hi = min(vals), max(vals)
        full_lo, full_hi = data_range(res, name)
        full = max(full_hi - full_lo, 1e-9)
        pad = max(0.3 * (hi - lo), 0.05 * full)
        limits.append((lo - pad, hi + pad))
    ax.set_xlim(*limits[0])
    ax.set_ylim(*limits[1])
    ax.set_title(r"zoom on the special points: $\bar{H}$ over $T$, " + model_title(res), fontsize=10)
    place_legend(fig, ax, legend_handles(res, drawn, sp_styles, res.has_stable()))
    save(fig, res, "rod_zoom", svg, written)


# ----------------------------------------------------------------------------------------------------
# key frames
# ----------------------------------------------------------------------------------------------------

def load_orbit(path, phases):
    """Rows (t, segment, phase name, {state: value}) sorted by t."""
    table = Table(path)
    ts, segs = table.num("t"), table.num("segment")
    if ts is None or segs is None:
        raise ValueError("no t or segment column")
    if not phases:  # infer from the column names "<phase>.<state>"
        names = []
        for c in table.columns:
            if "." in c:
                p, s = c.split(".", 1)
                if p not in [q["name"] for q in names]:
                    names.append({"name": p, "states": []})
                next(q for q in names if q["name"] == p)["states"].append(s)
        phases = names
    if not phases:
        raise ValueError("no phase columns")
    cols = {p["name"]: {s: table.num("%s.%s" % (p["name"], s)) for s in p["states"]} for p in phases}
    rows = []
    for r in range(table.n):
        if not finite(ts[r], segs[r]) or segs[r] < 1:
            continue
        seg = int(round(segs[r]))
        phase = phases[(seg - 1) % len(phases)]["name"]
        state = {s: (c[r] if c is not None else math.nan) for s, c in cols[phase].items()}
        rows.append((ts[r], seg, phase, state))
    rows.sort(key=lambda row: (row[0], row[1]))
    if len(rows) < 2:
        raise ValueError("fewer than two samples")
    return rows


def state_at(rows, t):
    """Linear interpolation within a segment; nearest sample across a segment switch."""
    lo, hi = 0, len(rows) - 1
    if t <= rows[0][0]:
        return rows[0]
    if t >= rows[-1][0]:
        return rows[-1]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if rows[mid][0] <= t:
            lo = mid
        else:
            hi = mid
    a, b = rows[lo], rows[hi]
    if a[1] != b[1]:
        return a if t - a[0] < b[0] - t else b
    w = (t - a[0]) / (b[0] - a[0]) if b[0] > a[0] else 0.0
    state = {k: a[3][k] + w * (b[3].get(k, math.nan) - a[3][k]) for k in a[3]}
    return (t, a[1], a[2], state)


def reconstruct_slip_x(rows):
    """Adds "_x" (mass) and, in stance, "_foot" to every row's state.

    Horizontal velocity (flight: dx; stance: -dl sin(alpha) - dalpha l cos(alpha)) is integrated with the
    trapezoidal rule from x = 0; the foot stays where the stance began (geometrically exact in stance)."""
    out = []
    x_prev = t_prev = v_prev = None
    foot, seg_prev = None, None
    for t, seg, phase, st in rows:
        st = dict(st)
        if "l" in st:  # stance
            a, l, da, dl = st.get("alpha", 0.0), st.get("l", 1.0), st.get("dalpha", 0.0), st.get("dl", 0.0)
            v = -dl * math.sin(a) - da * l * math.cos(a)
            if foot is None or seg != seg_prev:
                x = 0.0 if x_prev is None else x_prev + 0.5 * (v_prev + v) * (t - t_prev)
                foot = x + l * math.sin(a)
            x = foot - l * math.sin(a)
            st["_foot"] = foot
        else:
            v = st.get("dx", 0.0)
            if not finite(v):
                v = 0.0
            x = 0.0 if x_prev is None else x_prev + 0.5 * (v_prev + v) * (t - t_prev)
            foot = None
        if not finite(x):
            x = x_prev if x_prev is not None else 0.0
        if not finite(v):
            v = 0.0
        st["_x"] = x
        st["_vx"] = v
        out.append((t, seg, phase, st))
        x_prev, t_prev, v_prev, seg_prev = x, t, v, seg
    return out


def zigzag(p0, p1, coils=5, width=0.06):
    """Points of a spring drawn from p0 to p1 (straight ends, zigzag in the middle)."""
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    length = math.hypot(dx, dy)
    if length < 1e-9:
        return [p0, p1]
    ux, uy = dx / length, dy / length
    nx, ny = -uy, ux
    pts = [p0]
    a, b = 0.25, 0.8
    k = 2 * coils
    for i in range(k + 1):
        s = a + (b - a) * i / k
        off = 0.0 if i in (0, k) else (width if i % 2 else -width)
        pts.append((p0[0] + ux * s * length + nx * off, p0[1] + uy * s * length + ny * off))
    pts.append(p1)
    return pts


class Mechanism:
    """Draws one model's mechanism.  shapes(state) -> list of primitives in local coordinates."""

    def __init__(self, res):
        self.model = res.model
        self.l0 = res.parameter("l0", 1.0)
        self.beta = res.parameter("beta", 0.3)
        self.note = ""
        if self.model == "rocking-block":
            self.note = "after the impact the motion is mirrored onto the right corner"

    def supported(self):
        return self.model in ("bouncing-ball", "rocking-block", "bouncing-rod", "slip")

    def prepare(self, rows):
        return reconstruct_slip_x(rows) if self.model == "slip" else rows

    def scale(self):
        return self.l0

    def min_spacing(self):
        return {"bouncing-ball": 1.25 * self.l0, "rocking-block": 0.0, "bouncing-rod": 1.3 * self.l0,
                "slip": 0.75 * self.l0}.get(self.model, self.l0)

    def track(self, row):
        """Point traced over time (centre of mass) in local coordinates."""
        t, seg, phase, st = row
        g = lambda k, d=0.0: st.get(k, d) if finite(st.get(k, d)) else d  # noqa: E731
        if self.model == "bouncing-ball":
            return (0.0, g("y") + 0.5 * self.l0)
        if self.model == "bouncing-rod":
            return (0.0, g("y"))
        if self.model == "rocking-block":
            a = g("alpha")
            w = 2 * self.l0 * math.sin(self.beta)
            cx, cy = self._rot(0.5 * w, self.l0 * math.cos(self.beta), a)
            return (w - cx if seg % 2 == 0 else cx, cy)
        if self.model == "slip":
            if "l" in st:
                return (g("_x"), g("l", self.l0) * math.cos(g("alpha")))
            return (g("_x"), g("y"))
        return (0.0, 0.0)

    @staticmethod
    def _rot(x, y, a):
        return (x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a))

    def shapes(self, row, colour):
        t, seg, phase, st = row
        g = lambda k, d=0.0: st.get(k, d) if finite(st.get(k, d)) else d  # noqa: E731
        out = []
        if self.model == "bouncing-ball":
            r = 0.5 * self.l0
            cy = g("y") + r
            out.append(("circle", (0.0, cy), r, dict(fc=colour, ec="black", lw=1.0, alpha=0.85)))
            out.append(("dot", (0.0, cy), dict(ms=2.5, color="black")))
        elif self.model == "rocking-block":
            a = g("alpha")
            w, h = 2 * self.l0 * math.sin(self.beta), 2 * self.l0 * math.cos(self.beta)
            corners = [self._rot(x, y, a) for x, y in ((0, 0), (w, 0), (w, h), (0, h))]
            com = self._rot(0.5 * w, 0.5 * h, a)
            pivot = (0.0, 0.0)
            if seg % 2 == 0:  # after the impact: rocking on the right corner (mirror image)
                corners = [(w - x, y) for x, y in corners]
                com = (w - com[0], com[1])
                pivot = (w, 0.0)
            out.append(("poly", corners, dict(fc=colour, ec="black", lw=1.0, alpha=0.85)))
            out.append(("line", [pivot, com], dict(color="white", lw=0.8, ls=":")))
            out.append(("dot", com, dict(ms=3, color="black")))
            out.append(("dot", pivot, dict(ms=4.5, color="#d62728")))
        elif self.model == "bouncing-rod":
            a, y = g("alpha"), g("y")
            hx, hy = 0.5 * self.l0 * math.cos(a), 0.5 * self.l0 * math.sin(a)
            left, right = (-hx, y - hy), (hx, y + hy)
            out.append(("line", [left, right], dict(color=colour, lw=3.0, solid_capstyle="round")))
            out.append(("dot", left, dict(ms=5.5, color="#d62728", mec="black", mew=0.6)))
            out.append(("dot", right, dict(ms=5.5, color="white", mec="black", mew=1.0)))
            out.append(("dot", (0.0, y), dict(ms=2.5, color="black")))
        elif self.model == "slip":
            stance = "l" in st
            x = g("_x")
            a = g("alpha")
            if stance:
                l = g("l", self.l0)
                foot = (g("_foot", x), 0.0)
                mass = (foot[0] - l * math.sin(a), l * math.cos(a))
                vy = g("dl") * math.cos(a) - g("dalpha") * l * math.sin(a)
                leg_colour = "#d62728"
            else:
                mass = (x, g("y"))
                foot = (mass[0] + self.l0 * math.sin(a), mass[1] - self.l0 * math.cos(a))
                vy = g("dy")
                leg_colour = "#1f77b4"
            vx = g("_vx")
            out.append(("line", zigzag(foot, mass, width=0.045 * self.l0), dict(color=leg_colour, lw=1.3)))
            out.append(("dot", foot, dict(ms=3.5, color=leg_colour)))
            k = 0.18 * self.l0
            if math.hypot(vx, vy) * k > 0.02 * self.l0:
                out.append(("arrow", mass, (vx * k, vy * k), dict(color="0.35")))
            out.append(("circle", mass, 0.075 * self.l0, dict(fc="0.15", ec="black", lw=0.8, zorder=5)))
        return out


def bbox_of(shapes):
    xs, ys = [], []
    for s in shapes:
        if s[0] == "circle":
            (cx, cy), r = s[1], s[2]
            xs += [cx - r, cx + r]
            ys += [cy - r, cy + r]
        elif s[0] in ("line", "poly"):
            xs += [p[0] for p in s[1]]
            ys += [p[1] for p in s[1]]
        elif s[0] == "dot":
            xs.append(s[1][0])
            ys.append(s[1][1])
        elif s[0] == "arrow":
            xs += [s[1][0], s[1][0] + s[2][0]]
            ys += [s[1][1], s[1][1] + s[2][1]]
    xs = [v for v in xs if finite(v)]
    ys = [v for v in ys if finite(v)]
    if not xs or not ys:
        return (0.0, 0.0, 0.0, 0.0)
    return (min(xs), max(xs), min(ys), max(ys))


def draw_shapes(ax, shapes, dx):
    for s in shapes:
        kind = s[0]
        if kind == "circle":
            (cx, cy), r, kw = s[1], s[2], dict(s[3])
            kw.setdefault("zorder", 4)
            ax.add_patch(Circle((cx + dx, cy), r, **kw))
        elif kind == "poly":
            kw = dict(s[2])
            kw.setdefault("zorder", 3)
            ax.add_patch(Polygon([(x + dx, y) for x, y in s[1]], closed=True, **kw))
        elif kind == "line":
            kw = dict(s[2])
            kw.setdefault("zorder", 4)
            ax.plot([p[0] + dx for p in s[1]], [p[1] for p in s[1]], **kw)
        elif kind == "dot":
            kw = dict(s[2])
            kw.setdefault("zorder", 6)
            ax.plot([s[1][0] + dx], [s[1][1]], marker="o", ls="none", **kw)
        elif kind == "arrow":
            kw = s[3]
            ax.annotate("", xy=(s[1][0] + dx + s[2][0], s[1][1] + s[2][1]), xytext=(s[1][0] + dx, s[1][1]),
                        arrowprops=dict(arrowstyle="-|>", color=kw.get("color", "0.3"), lw=0.9,
                                        shrinkA=0, shrinkB=0, mutation_scale=7), zorder=7)


def orbit_layout(mech, rows, n_frames):
    """Frame times, their states, shapes and horizontal offsets, plus the traced path."""
    t0, t1 = rows[0][0], rows[-1][0]
    period = t1 - t0
    times = [t0 + period * i / (n_frames - 1) for i in range(n_frames)]
    states = [state_at(rows, t) for t in times]
    shapes = [mech.shapes(s, "#8fb8de") for s in states]
    boxes = [bbox_of(s) for s in shapes]
    widths = [b[1] - b[0] for b in boxes]
    gap = 0.3 * mech.scale()
    spacing = max(max(widths) + gap, mech.min_spacing())
    local_x = [mech.track(s)[0] for s in states]
    # frames must not overlap, whatever the (physical) horizontal motion does between them
    for i in range(n_frames - 1):
        right_i = boxes[i][1]
        left_next = boxes[i + 1][0]
        spacing = max(spacing, right_i - left_next + gap)
    offsets = [spacing * i for i in range(n_frames)]
    path = []
    for row in rows:
        x, y = mech.track(row)
        frac = (row[0] - t0) / period if period > 0 else 0.0
        path.append((x + spacing * (n_frames - 1) * frac, y))
    return times, states, offsets, path, local_x


def figure_keyframes(res, svg, written, n_frames=9):
    entries = [o for o in (res.summary.get("orbits") or []) if isinstance(o, dict)]
    if not entries:
        return
    mech = Mechanism(res)
    if not mech.supported():
        warn("no key-frame drawing for model '%s'; keyframes.png skipped" % res.model)
        return
    if len(entries) > 6:
        warn("%d orbits listed; key frames drawn for the first 6" % len(entries))
        entries = entries[:6]
    orbits = []
    for k, o in enumerate(entries):
        fname = o.get("file") or "orbit-%d.csv" % k
        path = os.path.join(res.dir, fname)
        if not os.path.isfile(path):
            warn("orbit file %s is missing" % fname)
            continue
        try:
            rows = mech.prepare(load_orbit(path, res.phases))
        except (OSError, ValueError, csv.Error) as e:
            warn("skipping %s: %s" % (fname, e))
            continue
        if rows[-1][0] <= rows[0][0]:
            warn("skipping %s: zero duration" % fname)
            continue
        orbits.append((o, rows))
    if not orbits:
        return

    layouts = [orbit_layout(mech, rows, n_frames) for _, rows in orbits]
    cmap = plt.get_cmap("Blues")
    spans = []
    for (o, rows), (times, states, offsets, path, _) in zip(orbits, layouts):
        boxes = [bbox_of(mech.shapes(s, "k")) for s in states]
        xmin = min(b[0] + dx for b, dx in zip(boxes, offsets))
        xmax = max(b[1] + dx for b, dx in zip(boxes, offsets))
        ymax = max([b[3] for b in boxes] + [p[1] for p in path if finite(p[1])])
        ymin = min([b[2] for b in boxes] + [0.0])
        spans.append((xmin, xmax, ymin, ymax))
    s = mech.scale()
    pad = 0.25 * s
    limits = []
    for xmin, xmax, ymin, ymax in spans:
        limits.append([xmin - pad, xmax + pad, ymin - 0.3 * s, ymax + 0.25 * s])
    # one common scale (inches per unit length) for all rows, so that the orbits compare directly
    width_in, left_in, right_in = 11.0, 0.15, 0.15
    axis_w = width_in - left_in - right_in
    k = axis_w / max(l[1] - l[0] for l in limits)
    k = min(k, 4.2 / max(l[3] - l[2] for l in limits))
    title_in, gap_in, top_in, bottom_in, min_h = 0.34, 0.14, 0.5, 0.42, 0.9
    for l in limits:
        if (l[3] - l[2]) * k < min_h:
            l[3] = l[2] + min_h / k
    height_in = top_in + bottom_in + sum((l[3] - l[2]) * k + title_in + gap_in for l in limits)
    fig = plt.figure(figsize=(width_in, height_in))
    axes = []
    y_in = height_in - top_in
    for l in limits:
        h = (l[3] - l[2]) * k
        y_in -= title_in + h
        w = (l[1] - l[0]) * k
        axes.append(fig.add_axes([left_in / width_in, y_in / height_in, w / width_in, h / height_in]))
        y_in -= gap_in
    for ax, (o, rows), (times, states, offsets, path, _), span, lim in zip(axes, orbits, layouts, spans,
                                                                         limits):
        xmin, xmax, ymin, ymax = span
        ax.set_xlim(lim[0], lim[1])
        ax.set_ylim(lim[2], lim[3])
        ax.set_aspect("equal", adjustable="box", anchor="W")
        ax.axhline(0.0, color="black", lw=1.2, zorder=1)
        ax.fill_between([lim[0], lim[1]], -0.08 * s, 0.0, facecolor="none", edgecolor="0.55",
                        hatch="////", lw=0.0, zorder=0)
        pts = [p for p in path if finite(*p)]
        if pts:
            ax.plot(*zip(*pts), color="0.6", lw=0.8, ls=":", zorder=1)
        n = len(states)
        for i, (t, st, dx) in enumerate(zip(times, states, offsets)):
            colour = cmap(0.35 + 0.55 * i / max(n - 1, 1))
            draw_shapes(ax, mech.shapes(st, colour), dx)
            cx = bbox_of(mech.shapes(st, colour))
            ax.text(0.5 * (cx[0] + cx[1]) + dx, -0.11 * s, "t=%.2f" % t, ha="center", va="top", fontsize=7,
                    color="0.3")
        label = str(o.get("label") or "orbit")
        H, T = to_float(o.get("H")), to_float(o.get("T"))
        if not finite(T):
            T = rows[-1][0] - rows[0][0]
        title = label
        if finite(H):
            title += r",  $\bar{H}=%.4g\ m_\mathrm{o} g l_\mathrm{o}$" % H
        title += r",  $T=%.4g\ \sqrt{l_\mathrm{o}/g}$" % T
        if "branch" in o:
            title += "  (branch %s)" % o.get("branch")
        ax.set_title(title, fontsize=9.5, loc="left")
        ax.set_axis_off()
        # scale bar of length l0
        x0 = lim[1] - 1.05 * s
        ax.plot([x0, x0 + s], [lim[3] - 0.12 * s] * 2, color="black", lw=1.5)
        ax.text(x0 + 0.5 * s, lim[3] - 0.1 * s, r"$l_\mathrm{o}$", ha="center", va="bottom", fontsize=8)
    notes = []
    if mech.model == "slip":
        notes = [Line2D([], [], color="#d62728", lw=1.5, label="leg in stance"),
                 Line2D([], [], color="#1f77b4", lw=1.5, label="leg in flight"),
                 Line2D([], [], color="0.35", lw=0.9, marker=">", ms=4, label="velocity of the mass")]
    elif mech.model == "bouncing-rod":
        notes = [Line2D([], [], marker="o", ls="none", color="#d62728", mec="black", label="left end"),
                 Line2D([], [], marker="o", ls="none", color="white", mec="black", label="right end")]
    elif mech.model == "rocking-block":
        notes = [Line2D([], [], marker="o", ls="none", color="#d62728", label="pivot corner")]
    notes.append(Line2D([], [], color="0.6", lw=0.8, ls=":", label="centre of mass (time runs left to right)"))
    fig.legend(handles=notes, loc="lower left", ncol=len(notes), fontsize=8, frameon=False,
               bbox_to_anchor=(left_in / width_in, 0.0))
    head = "Key frames, %s" % model_title(res)
    if mech.note:
        head += "; " + mech.note
    fig.suptitle(head, fontsize=10.5, x=left_in / width_in, y=1.0 - 0.12 / height_in, ha="left", va="top")
    save(fig, res, "keyframes", svg, written)


# ----------------------------------------------------------------------------------------------------
# main
# ----------------------------------------------------------------------------------------------------

def parse_args(argv):
    parser = argparse.ArgumentParser(prog="hybridcont_plot.py",
                                     description="Figures from the results folder of 'hybridcont run'.")
    parser.add_argument("results_dir", help="folder with summary.json and the branch/orbit CSV files")
    parser.add_argument("--svg", action="store_true", help="also write every figure as SVG")
    parser.add_argument("--frames", type=int, default=9,
                        help="key frames per orbit, equally spaced from t = 0 to T (2..16, default 9)")
    args = parser.parse_args(argv)
    if not 2 <= args.frames <= 16:
        parser.error("--frames must be between 2 and 16")
    return args


def main(argv):
    args = parse_args(argv)
    try:
        res = Results(args.results_dir)
    except PlotError as e:
        print("hybridcont_plot: error: %s" % e, file=sys.stderr)
        return 2
    jobs = [("H_T", lambda w: figure_h_t(res, args.svg, w))]
    if has_nonzero_xi(res):
        jobs.append(("H_T_xi", lambda w: figure_h_t_xi(res, args.svg, w)))
    if res.model == "slip":
        jobs.append(("slip_durations", lambda w: figure_slip_durations(res, args.svg, w)))
        jobs.append(("slip_speed", lambda w: figure_slip_speed(res, args.svg, w)))
    if res.model == "bouncing-rod":
        jobs.append(("rod_t2", lambda w: figure_rod_t2(res, args.svg, w)))
        jobs.append(("rod_zoom", lambda w: figure_rod_zoom(res, args.svg, w)))
    jobs.append(("keyframes", lambda w: figure_keyframes(res, args.svg, w, args.frames)))
    written, failed = [], []
    for name, job in jobs:
        try:
            job(written)
        except Exception as e:  # keep going: one bad figure must not lose the others
            plt.close("all")
            failed.append(name)
            print("hybridcont_plot: error: %s failed: %s: %s" % (name, type(e).__name__, e), file=sys.stderr)
    for path in written:
        print(path)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
