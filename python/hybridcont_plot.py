#!/usr/bin/env python3
"""Figures for the results of ``hybridcont run`` (paper §4: bifurcation diagrams and key frames).

Usage::

    /usr/bin/python3 hybridcont_plot.py RESULTS_DIR [--svg] [--pdf] [--all] [--x COLUMN --y COLUMN] [--frames N]

Reads RESULTS_DIR/summary.json and the CSV files it names, writes the figures into RESULTS_DIR as PNG
(200 dpi; with ``--svg`` and ``--pdf`` also as vector files, text kept as text, fonts embedded) and prints
the paths of the files written, one per line.  ``--x C --y D`` draws only the diagram of column D over
column C (D_C.png), in the same style as the main diagram.
Exits with status 2 and a one-line message on stderr (naming the file and the field) when the folder or
summary.json is missing or malformed, with status 1 when some figure could not be drawn (the others are
still written).  Only the standard library and matplotlib (Agg backend) are used.

The script knows no model.  Everything model-specific -- the title, the extra figures, how the mechanism
is drawn -- comes from the results folder, where the writer put the model's presentation
(include/hybridcont/model_setup.h), so a model file gets the same figures as a built-in model.

Data contract (fields are looked up by name; unknown fields and columns are ignored)
-----------------------------------------------------------------------------------
summary.json
    model           the model's name (the title when the presentation has none)
    parameters      {name: value}; listed in the titles
    phases          [{"name": str, "states": [str, ...]}, ...]; m = number of phases
    unknowns        names of the components of u (used to read special points' "u")
    branches        [{"id", "file", "parent" (special point id or -1), "points", "termination", "direction"}]
    special_points  [{"id", "type" (SB|TP|BP|PD|start|...), "branch", "index", "H", "T",
                      "status" (located|bracketed), "precision", "u"}]
    orbits          [{"file", "branch", "index", "H", "T", "label" (the orbit's family name)}]   (optional)
    presentation    (optional: folders written before it existed get the generic figures only)
        title       str, used in every figure title
        quantities  [column name, ...]: per-point quantities written as columns of the branch files
        families    [family name, ...]
        figures     [{"file": "NAME.png", "title": str, "x": column, "y": [column, ...], "zoom": bool}]
        drawing     {"ground": bool, "mass_radius": float,
                     "phases": {phase name: {"lines": [[point, point, ...], ...], "masses": [point, ...]}}}
branch-<id>.csv
    header row, then one row per point.  Used columns: H, T, xi (or xi1), t1..t<m+1>, x<i>_<state>, physical (1/0),
    classification (word), index (to find special points without "u"), stable (1/0/empty, optional), and
    any column a figure names (e.g. a quantity).  Empty or non-numeric cells are read as NaN.
orbit-<k>.csv
    columns t, segment, phase (the sample's phase name), "<phase>.<state>" ..., and draw.<point>.x,
    draw.<point>.y for every drawing point, empty where the sample's phase does not draw the point.
    t runs from 0 to T over one period.  The points are in the model's length unit and already contain
    the mechanism's own horizontal motion.

Figures
-------
H_T.png          the main diagram: H-bar over T for every branch (paper Fig. HoverT).  Families in a
                 parameter p instead (summary "options.free") give <y>_<p>.png: the period over p, or,
                 where the period says nothing (constant, or T p or T / p constant: a forced system),
                 the section's first state that changes.
                 Drawn by family (summary "branches[].family"), not by branch: one Okabe-Ito colour per
                 family (colour-blind safe), one legend entry each; branches without physical orbits
                 thin, light grey and unlabelled ("other branches").  Physical stretches solid, the
                 family's others dashed and lighter, stable ones thick with a dark rim; a family lying on
                 another in the projection (mirror images) in long dashes on top.  The view encloses the
                 families' physical orbits (--all: everything).  Special points on physical stretches are
                 marked and labelled (SB filled dot, TP open circle, BP square, PD diamond, start star;
                 only bracketed ones with a grey edge); labels of coinciding points join ("BP2/PD3"),
                 and each label takes a free place around its point.  Others get a small grey marker.
                 A branch whose projection collapses to one point is drawn as a marker.
H_T_xi.png       (only when some xi != 0) the same in three dimensions T, xi, H-bar, showing the
                 branches that differ only in xi (e.g. an equilibrium family).
<figures[i].file>  the presentation's figures: the y columns over the x column in one axes, drawn like
                 H_T.png; the first y column as lines, each further one with open markers of its own
                 shape.  With "zoom", the axis limits enclose the special points instead of all branches.
keyframes.png    key frames of up to 6 orbits of summary["orbits"] (one row each, equally spaced instants
                 from t = 0 to T, placed left to right): each sample's phase draws its lines (polylines
                 through the named points, one colour per phase) and masses (discs), above the ground
                 line y = 0 when the drawing has one; the masses' paths are dotted.
"""

import argparse
import csv
import json
import math
import os
import sys

plt = Line2D = Circle = patheffects = None  # matplotlib, imported once the results have been read (import_matplotlib)


def import_matplotlib():
    """matplotlib takes half a second to import: a damaged folder or a bad argument is reported first."""
    global plt, Line2D, Circle, patheffects
    if plt is None:
        import matplotlib
        matplotlib.use("Agg")
        matplotlib.rcParams["svg.fonttype"] = "none"  # SVG text stays text (editable, searchable)
        matplotlib.rcParams["pdf.fonttype"] = 42      # PDF fonts embedded as TrueType (journals ask for it)
        import matplotlib.pyplot as pyplot
        import matplotlib.patheffects as effects
        from matplotlib.lines import Line2D as line_2d
        from matplotlib.patches import Circle as circle
        plt, Line2D, Circle, patheffects = pyplot, line_2d, circle, effects



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
        rows, self.lines = [], []
        with open(path, newline="") as f:
            reader = csv.reader(f)
            for r in reader:
                if r and any(c.strip() for c in r):
                    rows.append(r)
                    self.lines.append(reader.line_num)
        if not rows:
            raise ValueError("empty file (no header)")
        self.columns = [c.strip() for c in rows[0]]
        self.rows = rows[1:]
        self.lines = self.lines[1:]  # the file's line number of each row, for messages
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


def is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def malformed(path, field, problem):
    return PlotError("%s is malformed: '%s' %s" % (path, field, problem))


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
        raise PlotError("cannot read %s: %s" % (path, (str(e).splitlines() or [type(e).__name__])[0]))
    except RecursionError:
        raise PlotError("cannot read %s: nested too deeply" % path)
    if not isinstance(summary, dict):
        raise PlotError("%s is malformed: expected a JSON object" % path)
    for key in ("branches", "special_points", "orbits", "phases", "unknowns"):
        if key in summary and summary[key] is not None and not isinstance(summary[key], list):
            raise malformed(path, key, "must be a list")
    if "branches" not in summary:
        raise PlotError("%s is malformed: no 'branches' list" % path)
    for key in ("branches", "special_points", "orbits"):
        for i, item in enumerate(summary.get(key) or []):
            if not isinstance(item, dict):
                raise malformed(path, "%s[%d]" % (key, i), "must be an object")
            # ids and row indices are compared and used as dict keys: numbers only
            for field in ("id", "branch", "parent", "index"):
                if item.get(field) is not None and not (is_number(item[field]) and math.isfinite(item[field])):
                    raise malformed(path, "%s[%d].%s" % (key, i, field), "must be a number")
            if key != "special_points" and item.get("file") is not None and not (
                    isinstance(item["file"], str) and item["file"].strip()):
                raise malformed(path, "%s[%d].file" % (key, i), "must be a file name")
            # a file of this folder: never a path that reads elsewhere
            name = item.get("file")
            if key != "special_points" and isinstance(name, str) and (
                    os.path.basename(name) != name or name in (".", "..") or "\0" in name):
                raise malformed(path, "%s[%d].file" % (key, i), "must be a file name without a folder, got '%s'" % name)
    if not isinstance(summary.get("parameters", {}) or {}, dict):
        raise malformed(path, "parameters", "must be an object")
    if summary.get("model") is not None and not isinstance(summary["model"], str):
        raise malformed(path, "model", "must be a string")
    status = summary.get("status", "complete")  # folders written before the status existed are complete
    if not isinstance(status, str):
        raise malformed(path, "status", "must be a string")
    if status != "complete":
        why = summary.get("status_message")
        warn("%s says the run is %s%s: drawing what it holds" % (
            path, "incomplete ('%s')" % status, ": %s" % why if isinstance(why, str) and why else ""))
    return summary, path


def read_names(obj, key, path, field, required=False):
    """obj[key] as a list of non-empty strings ([] when absent and not required)."""
    if key not in obj or obj[key] is None:
        if required:
            raise PlotError("%s is malformed: no '%s'" % (path, field))
        return []
    value = obj[key]
    if isinstance(value, str):  # a single name written without the list
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) and v.strip() for v in value):
        raise malformed(path, field, "must be a list of names")
    return [v.strip() for v in value]


def read_presentation(summary, path):
    """The model's presentation as plain dicts, or None when summary.json has none (an older writer).

    Every field is checked here, so that a bad folder fails once with a message naming the field instead
    of half-way through a figure."""
    p = summary.get("presentation")
    if p is None:
        return None
    if not isinstance(p, dict):
        raise malformed(path, "presentation", "must be an object")
    title = p.get("title")
    if title is not None and not isinstance(title, str):
        raise malformed(path, "presentation.title", "must be a string")
    out = {"title": (title or "").strip(),
           "quantities": read_names(p, "quantities", path, "presentation.quantities"),
           "families": read_names(p, "families", path, "presentation.families"),
           "figures": [], "drawing": None}

    figures = p.get("figures") or []
    if not isinstance(figures, list):
        raise malformed(path, "presentation.figures", "must be a list")
    for i, f in enumerate(figures):
        field = "presentation.figures[%d]" % i
        if not isinstance(f, dict):
            raise malformed(path, field, "must be an object")
        name = f.get("file")
        if not isinstance(name, str) or not name.strip():
            raise PlotError("%s is malformed: no '%s.file'" % (path, field))
        name = name.strip()
        if os.path.basename(name) != name or name in (".", ".."):
            raise malformed(path, field + ".file", "must be a file name without a folder, got '%s'" % name)
        stem, ext = os.path.splitext(name)
        if ext.lower() not in ("", ".png"):
            raise malformed(path, field + ".file", "must end in .png, got '%s'" % name)
        ftitle = f.get("title")
        if ftitle is not None and not isinstance(ftitle, str):
            raise malformed(path, field + ".title", "must be a string")
        x = f.get("x")
        if not isinstance(x, str) or not x.strip():
            raise PlotError("%s is malformed: no '%s.x' (a column name)" % (path, field))
        ys = read_names(f, "y", path, field + ".y", required=True)
        if not ys:
            raise malformed(path, field + ".y", "must name at least one column")
        zoom = f.get("zoom", False)
        if zoom is None:
            zoom = False
        if not isinstance(zoom, bool):
            raise malformed(path, field + ".zoom", "must be true or false")
        out["figures"].append({"name": stem, "file": stem + ".png", "title": (ftitle or "").strip(),
                               "x": x.strip(), "y": ys, "zoom": zoom})

    d = p.get("drawing")
    if d is not None:
        if not isinstance(d, dict):
            raise malformed(path, "presentation.drawing", "must be an object")
        ground = d.get("ground", True)
        if not isinstance(ground, bool):
            raise malformed(path, "presentation.drawing.ground", "must be true or false")
        radius = d.get("mass_radius", 0.05)
        if not is_number(radius) or not math.isfinite(radius) or radius < 0:
            raise malformed(path, "presentation.drawing.mass_radius", "must be a number >= 0")
        phases = d.get("phases") or {}
        if not isinstance(phases, dict):
            raise malformed(path, "presentation.drawing.phases", "must be an object {phase name: drawing}")
        drawing = {"ground": ground, "mass_radius": float(radius), "phases": {}}
        for name, ph in phases.items():
            field = "presentation.drawing.phases.%s" % name
            if not isinstance(ph, dict):
                raise malformed(path, field, "must be an object")
            lines = ph.get("lines") or []
            if not isinstance(lines, list):
                raise malformed(path, field + ".lines", "must be a list of point lists")
            drawing["phases"][name] = {
                "lines": [read_names({"l": line}, "l", path, "%s.lines[%d]" % (field, j))
                          for j, line in enumerate(lines)],
                "masses": read_names(ph, "masses", path, field + ".masses")}
        out["drawing"] = drawing
    return out


def phases_of(summary):
    phases = []
    for p in summary.get("phases") or []:
        if isinstance(p, dict) and isinstance(p.get("name"), str):
            states = [s for s in (p.get("states") or []) if isinstance(s, str)]
            phases.append({"name": p["name"], "states": states})
    return phases


def check_rows(table, path):
    """Every row as wide as the header, with a number in index, H and T (the columns the figures need)."""
    width = len(table.columns)
    numeric = [table.columns.index(c) for c in ("index", "H", "T") if c in table.columns]
    for row, line in zip(table.rows, table.lines):
        if len(row) != width:
            raise PlotError("%s:%d: %d cells, the header has %d (a garbage or truncated row)"
                            % (path, line, len(row), width))
        for j in numeric:
            try:
                float(row[j])
            except ValueError:
                raise PlotError("%s:%d: %s = '%s' is not a number" % (path, line, table.columns[j], row[j][:40]))


def load_branches(results_dir, summary):
    """List of dicts: id, entry (summary), table (Table or None)."""
    out = []
    for k, entry in enumerate(summary.get("branches") or []):
        bid = entry.get("id", k)
        fname = entry.get("file") or "branch-%s.csv" % bid
        path = os.path.join(results_dir, fname)
        # A branch file that summary.json names is part of the results: missing, unreadable or with
        # garbage rows, the folder is damaged (exit 2, the file and line named), not drawn in part.
        if not os.path.isfile(path):
            raise PlotError("%s names %s, which is missing" % (os.path.join(results_dir, "summary.json"), path))
        try:
            table = Table(path)
        except (OSError, ValueError, csv.Error) as e:
            raise PlotError("cannot read %s: %s" % (path, e))
        if table.num("H") is None or table.num("T") is None:
            raise PlotError("%s has no H or T column" % path)
        check_rows(table, path)
        out.append({"id": bid, "entry": entry, "table": table})
    # A run across the words of an automaton (summary "words"): every label names its branch's word.
    words = summary.get("words")
    if isinstance(words, list) and len(words) > 1:
        names = {}  # branch id -> its word's name (modes, with the transition where two modes share several)
        for w in words:
            if isinstance(w, dict) and isinstance(w.get("name"), str) and isinstance(w.get("branches"), list):
                for i in w["branches"]:
                    names[i] = w["name"]
        for b in out:
            word = b["entry"].get("word")
            if b["id"] in names:
                b["word"] = names[b["id"]]
            elif isinstance(word, list) and all(isinstance(w, str) for w in word):
                b["word"] = " > ".join(word)
    return out


# ----------------------------------------------------------------------------------------------------
# styling helpers
# ----------------------------------------------------------------------------------------------------

# Okabe & Ito's eight colours, distinguishable with every common colour-vision deficiency (yellow last: it
# is faint on white).  A family keeps its colour in every figure of a folder.
OKABE_ITO = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#56B4E9", "#E69F00", "#000000", "#F0E442"]
OTHER_COLOUR = "0.72"  # branches without physical orbits: light, behind the families
OTHER_LABEL = "other branches (no physical orbit)"


def family_colours(presentation_families, branches):
    """{family name: colour}: the presentation's families first, in its order, then the others as met."""
    order = [f for f in presentation_families or [] if isinstance(f, str)]
    for b in branches:
        f = b.get("family")
        if f and f not in order:
            order.append(f)
    return {f: OKABE_ITO[k % len(OKABE_ITO)] for k, f in enumerate(order)}


# The paper's models are written in units of a mass m_o, a length l_o and gravity g; other models (model
# files of the user's own) carry the units of their parameters, which the figures do not guess.
PAPER_MODELS = {"bouncing-ball", "rocking-block", "bouncing-rod", "slip", "ball-chain"}
UNITS = {"on": True}
# Options of the whole run: "all" draws every branch's special points as the families' are drawn; "formats"
# the file types each figure is written in.
FIGURE_OPTIONS = {"all": False, "formats": ["png"]}


def time_unit():
    return r"\ \ [\sqrt{l_\mathrm{o}/g}]" if UNITS["on"] else ""


GREEK = {"alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "iota", "kappa", "lambda", "mu",
         "nu", "xi", "pi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega"}


def symbol(name):
    """A state's name as mathematics: alpha -> α, dx -> ẋ (a leading d is a time derivative), th_st -> θ_st."""
    base, _, sub = name.partition("_")
    dot = base.startswith("d") and len(base) > 1 and (base[1:] in GREEK or len(base) == 2)
    core = base[1:] if dot else base
    if core in GREEK:
        core = "\\" + core
    elif core == "th":
        core = "\\theta"
    elif core == "ph":
        core = "\\phi"
    elif len(core) > 1:
        core = r"\mathrm{%s}" % core
    core = (r"\dot{%s}" % core) if dot else core
    return "$%s%s$" % (core, "_{\\mathrm{%s}}" % sub.replace("_", r"\_") if sub else "")


def state_column(name, res):
    """(phase name, state name) of a column x<i>_<state> (the state at the start of phase i), else None."""
    if res is None or not name.startswith("x") or "_" not in name:
        return None
    head, _, state = name.partition("_")
    if not head[1:].isdigit():
        return None
    i = int(head[1:]) - 1
    if 0 <= i < len(res.phases) and state in res.phases[i]["states"]:
        return res.phases[i]["name"], state
    return None


def axis_label(name, res=None):
    """The name of a column on an axis, in words with its symbol and unit: "energy H̄ [m g l]", "period T",
    "ẋ at the start of flight (x2_dx)", "parameter k"; a column the figures do not know keeps its name."""
    energy_unit = r"\ \ [m_\mathrm{o} g\, l_\mathrm{o}]" if UNITS["on"] else ""
    labels = {
        "H": r"energy $\bar{H}%s$" % energy_unit,
        "T": r"period $T%s$" % time_unit(),
        "xi": r"$\xi$",
    }
    if name in labels:
        return labels[name]
    if name.startswith("t") and name[1:].isdigit():
        phase = ""
        i = int(name[1:]) - 1
        if res is not None and res.phases:
            phase = " (%s)" % res.phases[i % len(res.phases)]["name"] if i < len(res.phases) + 1 else ""
        return r"duration $t_{%s}$%s%s" % (name[1:], phase, ("$%s$" % time_unit()) if UNITS["on"] else "")
    state = state_column(name, res)
    if state is not None:
        return "%s at the start of %s  (%s)" % (symbol(state[1]), state[0], name)
    if res is not None and name in res.parameters:
        return "parameter %s" % name
    return name


def column_symbol(name):
    """Short name of a column for legends: the symbol of H, T, xi and the durations, else the name."""
    symbols = {"H": r"$\bar{H}$", "T": r"$T$", "xi": r"$\xi$"}
    if name in symbols:
        return symbols[name]
    if name.startswith("t") and name[1:].isdigit():
        return r"$t_{%s}$" % name[1:]
    return name


def axis_label_of(names, res=None):
    """Label of an axis showing several columns: durations share their unit, other names are listed."""
    if len(names) == 1:
        return axis_label(names[0], res)
    if all(n.startswith("t") and n[1:].isdigit() for n in names):
        return "durations " + ", ".join(column_symbol(n) for n in names) + ("$%s$" % time_unit() if UNITS["on"] else "")
    return ", ".join(names)


def special_point_style(kind, bracketed, meanings=None):
    """Marker of a special point; its legend name is the code and its meaning as summary.json's
    "special_point_codes" gives it (the library's one definition of the codes)."""
    styles = {
        "SB": dict(marker="o", s=42, facecolor="black", edgecolor="black"),
        "TP": dict(marker="o", s=46, facecolor="white", edgecolor="black"),
        "BP": dict(marker="s", s=40, facecolor="black", edgecolor="black"),
        "PD": dict(marker="D", s=38, facecolor="#d62728", edgecolor="black"),
        "GR": dict(marker="v", s=46, facecolor="#17becf", edgecolor="black"),
        "NS": dict(marker="h", s=48, facecolor="#9467bd", edgecolor="black"),
        "start": dict(marker="*", s=120, facecolor="gold", edgecolor="black"),
    }
    style = dict(styles.get(kind, dict(marker="X", s=46, facecolor="#9467bd", edgecolor="black")))
    meaning = meanings.get(kind) if isinstance(meanings, dict) else None
    if not (isinstance(meaning, str) and meaning):
        style["name"] = str(kind)
    elif meaning.replace(" ", "-").endswith(kind):  # "start": its meaning alone ("singular start")
        style["name"] = meaning
    else:
        style["name"] = "%s %s" % (kind, meaning.replace("floquet", "Floquet").replace("neimark sacker", "Neimark-Sacker")
                                   .replace("krein", "Krein"))
    style["linewidth"] = 1.0
    if bracketed:
        style["edgecolor"] = "0.55"
        style["linewidth"] = 2.0
        if style["facecolor"] == "black":
            style["facecolor"] = "0.35"
        style["name"] = style["name"].split(" ")[0] + ", bracketed only"
    return style


def special_point_label(sp):
    """A special point's label as the library gives it (summary.json's "label": "PD4", what --at names); a folder
    written before 0.8.0 has none, and its label is its type and id, the rule the library had then."""
    label = sp.get("label")
    return label if isinstance(label, str) and label else "%s%s" % (sp.get("type", "?"), sp.get("id", ""))


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
    if branch.get("word"):
        label += " [%s]" % branch["word"]
    return label


def plot_runs(ax, xs, ys, phys, stable, colour, zs=None, over=False):
    """Draw one branch: runs of equal (physical, stable) flag, solid/dashed, sharing boundary points.

    Points with a non-finite coordinate break the line.  With `over` the branch lies on one drawn before
    (a mirror image in this projection): its physical runs are drawn in long dashes on top, so that both
    colours show.  Returns True when something was drawn."""
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
        cols = list(zip(*run))
        dashes = dict(ls=(0, (5.0, 5.0)), zorder=5) if over and k[0] else {}
        if colour == OTHER_COLOUR:  # a branch with no physical orbit: thin and behind everything
            ax.plot(*cols, color=colour, lw=0.9, ls=(0, (3.0, 2.0)), zorder=1)
        elif k[1]:  # stable: thick, with a dark rim, above the rest
            rim = [] if over else [patheffects.Stroke(linewidth=6.2, foreground="0.15"), patheffects.Normal()]
            ax.plot(*cols, **dict(dict(color=colour, lw=4.6, solid_capstyle="round", zorder=4,
                                       path_effects=rim), **dashes))
        elif k[0]:
            ax.plot(*cols, **dict(dict(color=colour, lw=1.9, solid_capstyle="round", zorder=3), **dashes))
        else:  # a family's non-physical stretch: its colour, dashed and lighter
            ax.plot(*cols, color=colour, lw=1.2, ls=(0, (4.0, 2.5)), alpha=0.6, zorder=2)

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
        self.summary, self.summary_path = load_summary(results_dir)
        self.presentation = read_presentation(self.summary, self.summary_path)
        self.model = str(self.summary.get("model") or "unknown")
        UNITS["on"] = self.model in PAPER_MODELS
        self.parameters = {k: to_float(v) for k, v in (self.summary.get("parameters") or {}).items()}
        self.phases = phases_of(self.summary)
        self.m = len(self.phases)
        self.unknowns = [u for u in (self.summary.get("unknowns") or []) if isinstance(u, str)]
        # A run with a free parameter at fixed H: the parameter takes H's place in the generic figures.
        free = (self.summary.get("options") or {}).get("free") or []
        self.family = free[0] if free and isinstance(free[0], str) else "H"
        self.special_points = [sp for sp in (self.summary.get("special_points") or []) if isinstance(sp, dict)]
        self.branches = load_branches(results_dir, self.summary)
        for o in self.summary.get("orbits") or []:  # checked before anything is drawn
            path = os.path.join(results_dir, o["file"]) if isinstance(o.get("file"), str) else None
            if path is not None and not os.path.isfile(path):
                raise PlotError("%s names %s, which is missing" % (self.summary_path, path))
        # A branch is drawn as its family (summary "family": named by the model's family rules where its
        # orbits are physical); branches without physical orbits are "other branches", light and unlabelled.
        for b in self.branches:
            f = b["entry"].get("family")
            b["family"] = f if isinstance(f, str) and f else None
            declared = (self.presentation or {}).get("families") or []
            if (b["family"] and b.get("word") and b["family"] not in declared and b["word"] not in b["family"]
                    and " > " not in b["family"]):
                b["family"] += " [%s]" % b["word"]
        colours = family_colours((self.presentation or {}).get("families"), self.branches)
        for b in self.branches:
            b["colour"] = colours[b["family"]] if b["family"] else OTHER_COLOUR
            b["label"] = b["family"] or OTHER_LABEL
            b["detail"] = branch_label(b, self.special_points)
        self.by_id = {b["id"]: b for b in self.branches}

    def has_stable(self):
        return any(b["table"] is not None and b["table"].num("stable") is not None
                   and any(s == 1 for s in b["table"].num("stable")) for b in self.branches)

    def column(self, branch, name):
        """Branch column by name; None when absent."""
        t = branch["table"]
        if t is None:
            return None
        if name == "xi" and not t.has("xi") and t.has("xi1"):  # several first integrals: xi1..xik
            return t.num("xi1")
        return t.num(name)

    def sp_value(self, sp, name):
        """Coordinate `name` of a special point: from its own field, from "u", or from its branch rows."""
        if name in ("H", "T") and finite(to_float(sp.get(name))):
            return to_float(sp.get(name))
        u = sp.get("u")
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
        index = to_float(sp.get("index"))
        if col is None or not finite(index):
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
        if row is None:
            return math.nan
        w = self._weight_after(branch, row, u)
        if w > 0 and row + 1 < len(col) and finite(col[row], col[row + 1]):
            return col[row] + w * (col[row + 1] - col[row])
        return col[row]

    def _weight_after(self, branch, row, u):
        """Where a special point found "after point `row`" lies towards the next row, in [0, 1].

        A column that is no unknown (a quantity) is known at the branch points only; the weight comes from
        the unknowns, which the point carries in "u", by least squares along the chord to the next row."""
        if not isinstance(u, list) or len(u) != len(self.unknowns) or row + 1 >= branch["table"].n:
            return 0.0
        num = den = 0.0
        for name, value in zip(self.unknowns, u):
            col = self.column(branch, name)
            v = to_float(value)
            if col is None or not finite(v, col[row], col[row + 1]):
                continue
            d = col[row + 1] - col[row]
            num += (v - col[row]) * d
            den += d * d
        return min(1.0, max(0.0, num / den)) if den > 0 else 0.0


# ----------------------------------------------------------------------------------------------------
# bifurcation diagrams
# ----------------------------------------------------------------------------------------------------

def on_physical_stretch(res, sp):
    """Whether a special point lies where its branch's orbits are physical (either neighbouring point)."""
    branch = res.by_id.get(sp.get("branch"))
    if branch is None or branch["table"] is None or not branch["family"]:
        return sp.get("type") == "start"
    phys = branch["table"].num("physical")
    index = to_float(sp.get("index"))
    if phys is None or not finite(index):
        return False
    row = int(index)
    return any(0 <= r < len(phys) and phys[r] == 1 for r in (row, row + 1))


def draw_special_points(ax, res, xname, yname, zname=None, annotate=True, only=None):
    """Markers of the special points; returns {legend name: style} of those drawn.

    Points where the orbits are physical get their marker and a label (placed later by place_labels, so
    that labels of coincident points merge and none overlaps another); the others a small light marker,
    unlabelled, unless the figure shows every branch's points (--all)."""
    used = {}
    labels = getattr(ax, "_hc_labels", [])
    for sp in res.special_points:
        kind = str(sp.get("type", "?"))
        if only is not None and not only(sp):
            continue
        x, y = res.sp_value(sp, xname), res.sp_value(sp, yname)
        z = res.sp_value(sp, zname) if zname else 0.0
        if not finite(x, y, z):
            continue
        style = special_point_style(kind, str(sp.get("status", "located")) != "located",
                                    res.summary.get("special_point_codes"))
        main = on_physical_stretch(res, sp) or FIGURE_OPTIONS["all"]
        kw = dict(marker=style["marker"], s=style["s"], facecolors=style["facecolor"],
                  edgecolors=style["edgecolor"], linewidths=style["linewidth"], zorder=6)
        if not main:
            kw.update(s=style["s"] * 0.35, facecolors="0.85" if style["facecolor"] != "white" else "white",
                      edgecolors="0.6", linewidths=0.7, zorder=2)
        if zname:
            ax.scatter([x], [y], [z], depthshade=False, **kw)
        else:
            ax.scatter([x], [y], **kw)
            if annotate and kind != "start" and main:
                labels.append((x, y, special_point_label(sp)))
        if main:
            used[style["name"]] = style
    ax._hc_labels = labels
    return used


def place_labels(ax, fontsize=7):
    """Writes the special points' labels gathered on ax without collisions.

    Labels of points that coincide on the figure (within 3 pixels: a PD and a BP at one orbit) are joined
    ("BP2/PD3").  Each label takes the first of 12 positions around its point (near ones first) whose box
    overlaps no label placed before, no marker and no axis edge; when none is free, the least crowded one."""
    labels = getattr(ax, "_hc_labels", [])
    if not labels:
        return
    ax.get_xlim(), ax.get_ylim()  # settles the autoscaled limits, so that transData is final
    fig = ax.figure
    px = fig.dpi / 72.0
    groups = []
    for x, y, text in labels:
        X, Y = ax.transData.transform((x, y))
        for g in groups:
            if abs(g["X"] - X) <= 3 and abs(g["Y"] - Y) <= 3:
                if text not in g["texts"]:
                    g["texts"].append(text)
                break
        else:
            groups.append({"x": x, "y": y, "X": X, "Y": Y, "texts": [text]})
    box = ax.get_window_extent()
    markers = [(g["X"] - 5 * px, g["Y"] - 5 * px, g["X"] + 5 * px, g["Y"] + 5 * px) for g in groups]
    placed = []

    def overlap(a, b):
        w = min(a[2], b[2]) - max(a[0], b[0])
        h = min(a[3], b[3]) - max(a[1], b[1])
        return w * h if w > 0 and h > 0 else 0.0

    for g in sorted(groups, key=lambda g: (g["X"], g["Y"])):
        text = "/".join(sorted(g["texts"], key=lambda t: (t.rstrip("0123456789"), int("0" + t.lstrip("ABCDEFGHIJKLMNOPQRSTUVWXYZ")))))
        w, h = 0.62 * fontsize * len(text) * px + 2 * px, 1.25 * fontsize * px
        best = None
        for r in (6, 14):
            for dx, dy in ((1, 0.4), (1, -1.4), (-1, 0.4), (-1, -1.4), (0, 1), (0, -2.2)):
                ox = r * px if dx > 0 else (-r * px - w if dx < 0 else -w / 2)
                oy = dy * (r * 0.6) * px if dx != 0 else (r * px if dy > 0 else -r * px - h)
                cand = (g["X"] + ox, g["Y"] + oy, g["X"] + ox + w, g["Y"] + oy + h)
                cost = sum(overlap(cand, q) for q in placed) + sum(overlap(cand, m) for m in markers)
                if cand[0] < box.x0 or cand[2] > box.x1 or cand[1] < box.y0 or cand[3] > box.y1:
                    cost += w * h
                if best is None or cost < best[0] - 1e-9:
                    best = (cost, cand, dx, ox, oy)
                if cost == 0:
                    break
            if best[0] == 0:
                break
        _, cand, dx, ox, oy = best
        placed.append(cand)
        # the text's near edge at the box's near edge: the estimated width only reserves room
        ha, tx = {1: ("left", ox), -1: ("right", ox + w), 0: ("center", ox + w / 2)}[dx]
        ax.annotate(text, (g["x"], g["y"]), xytext=(tx / px, oy / px), textcoords="offset points",
                    fontsize=fontsize, color="0.15", ha=ha, va="bottom", zorder=7,
                    bbox=dict(boxstyle="square,pad=0.05", fc="white", ec="none", alpha=0.8))
    ax._hc_labels = []


def legend_handles(res, branches_drawn, sp_styles, stable=False, extra=()):
    """One entry per family drawn (in the colour order), the light "other branches", the line styles and
    the kinds of special point drawn."""
    handles, seen = [], set()
    for b in sorted(branches_drawn, key=lambda b: (b["family"] is None, OKABE_ITO.index(b["colour"])
                                                   if b["colour"] in OKABE_ITO else 99)):
        if b["label"] in seen:
            continue
        seen.add(b["label"])
        if b["family"] is None:
            handles.append(Line2D([], [], color=OTHER_COLOUR, lw=0.9, ls=(0, (3.0, 2.0)), label=b["label"]))
        else:
            handles.append(Line2D([], [], color=b["colour"], lw=2.4, label=b["label"]))
    handles.append(Line2D([], [], color="0.2", lw=1.9, label="physical"))
    handles.append(Line2D([], [], color="0.2", lw=1.2, ls=(0, (4.0, 2.5)), alpha=0.6, label="not physical"))
    if stable:
        handles.append(Line2D([], [], color="0.5", lw=4.6, label="stable",
                              path_effects=[patheffects.Stroke(linewidth=6.2, foreground="0.15"),
                                            patheffects.Normal()]))
    handles.extend(extra)
    for name in sorted(sp_styles):
        st = sp_styles[name]
        handles.append(Line2D([], [], marker=st["marker"], ls="none", ms=math.sqrt(st["s"]) * 1.05,
                              mfc=st["facecolor"], mec=st["edgecolor"], mew=st["linewidth"], label=name))
    return handles


def place_legend(fig, ax, handles):
    place_labels(ax)
    ncol = 1 if len(handles) <= 16 else 2
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False,
              ncol=ncol, borderaxespad=0.0, handlelength=2.6)


def same_curve(a, b):
    """Whether two drawn curves (lists of (x, y)) are the same points, to 1e-9 of their size."""
    if len(a) != len(b) or not a:
        return False
    scale = max(1.0, max(abs(v) for p in a for v in p))
    return all(abs(p[0] - q[0]) <= 1e-9 * scale and abs(p[1] - q[1]) <= 1e-9 * scale for p, q in zip(a, b))


def focus_on_families(ax, res, xname, yname, margin=0.06):
    """Limits enclosing the families' physical orbits (the other branches, and the families' non-physical
    stretches, reach far off where nothing is physical); unchanged when no family is drawn or with --all."""
    if FIGURE_OPTIONS["all"]:
        return
    pts = []
    for b in res.branches:
        xs, ys, phys = res.column(b, xname), res.column(b, yname), b["table"].num("physical")
        if b["family"] is None or xs is None or ys is None or phys is None:
            continue
        pts += [(x, y) for x, y, p in zip(xs, ys, phys) if p == 1 and finite(x, y)]
    if not pts:
        return
    for axis, values in ((ax.set_xlim, [p[0] for p in pts]), (ax.set_ylim, [p[1] for p in pts])):
        lo, hi = min(values), max(values)
        pad = (hi - lo) * margin if hi > lo else max(abs(hi), 1.0) * 0.05
        axis(lo - pad, hi + pad)


def projection(ax, res, xname, yname, sp=True, annotate=True, sp_filter=None):
    """Draw all branches in the (xname, yname) projection; returns (branches drawn, special point styles).

    Families are drawn in their colours; a family lying on another one in this projection (a mirror image:
    forward and backward hopping have the same H and T) in long dashes on top of it."""
    stable = res.has_stable()
    drawn, curves = [], []
    for b in res.branches:
        xs, ys = res.column(b, xname), res.column(b, yname)
        if xs is None or ys is None:
            continue
        t = b["table"]
        st = t.num("stable") if stable else None
        curve = [(x, y) for x, y in zip(xs, ys) if finite(x, y)]
        over = b["family"] is not None and any(f != b["family"] and same_curve(curve, c) for f, c in curves)
        how = plot_runs(ax, xs, ys, t.num("physical"), st, b["colour"], over=over)
        if b["family"] is not None:
            curves.append((b["family"], curve))
        if how:
            drawn.append(b)
    sp_styles = draw_special_points(ax, res, xname, yname, annotate=annotate, only=sp_filter) if sp else {}
    ax.set_xlabel(axis_label(xname, res))
    ax.set_ylabel(axis_label(yname, res))
    ax.grid(True, color="0.9", lw=0.6)
    return drawn, sp_styles


def model_title(res):
    """The presentation's title (the model's name for older folders) with the parameters."""
    title = (res.presentation or {}).get("title") or res.model
    pars = ", ".join("%s=%g" % (k, v) for k, v in sorted(res.parameters.items()) if finite(v))
    return title + (" (%s)" % pars if pars else "")


def save(fig, res, name, svg, written):
    """Writes the figure in every format asked for (PNG at 200 dpi; SVG and PDF as vectors)."""
    formats = list(FIGURE_OPTIONS["formats"])
    if svg and "svg" not in formats:
        formats.append("svg")
    for ext in formats:
        path = os.path.join(res.dir, name + "." + ext)
        fig.savefig(path, dpi=200 if ext == "png" else None, bbox_inches="tight")
        written.append(path)
        record_figure(res.dir, path)
    plt.close(fig)


def record_figure(folder, path):
    """figures.txt lists every figure drawn into a results folder (one file name a line), so that the next study
    written there removes them all (docs/results-format.md): none is left beside a study it does not show."""
    manifest = os.path.join(folder, "figures.txt")
    names = []
    if os.path.exists(manifest):
        with open(manifest, encoding="utf-8") as f:
            names = [line for line in f.read().splitlines() if line]
    name = os.path.basename(path)
    if name in names:
        return
    with open(manifest + ".tmp", "w", encoding="utf-8") as f:
        f.write("".join(n + "\n" for n in names + [name]))
    os.replace(manifest + ".tmp", manifest)


def physical_values(res, name, of=None):
    """The column's values over the physical points of every branch (of(value, row) applied when given)."""
    vals = []
    for b in res.branches:
        col, phys = res.column(b, name), b["table"].num("physical")
        if col is not None and phys is not None:
            vals += [v if of is None else of(v, b, r) for r, (v, p) in enumerate(zip(col, phys))
                     if p == 1 and finite(v)]
    return [v for v in vals if finite(v)]


def constant(vals):
    return bool(vals) and max(vals) - min(vals) <= 1e-9 * max(1e-300, max(abs(v) for v in vals))


def period_is_forced(res):
    """Whether the period says nothing: constant, or in fixed ratio to the parameter (T = 2πn/w of a system
    forced at frequency w, T = n p of one forced with period p)."""
    if constant(physical_values(res, "T")):
        return True
    if res.family == "H":
        return False
    col = lambda v, b, r: v * res.column(b, res.family)[r]  # noqa: E731
    ratio = lambda v, b, r: v / res.column(b, res.family)[r]  # noqa: E731
    return constant(physical_values(res, "T", col)) or constant(physical_values(res, "T", ratio))


def main_diagram_axes(res):
    """(x, y, file name) of the main diagram.

    Families in H̄: H̄ over T (paper Fig. HoverT), H_T.png.  Families in a parameter p (a walker's slope, a
    forced system's frequency): over p, the period, unless the period says nothing (period_is_forced: a
    forced system's is the forcing's), then the first state at the section that changes; named <y>_<p>.png."""
    if res.family == "H":
        return "T", "H", "H_T"
    y = "T"
    if period_is_forced(res):
        # the first state at the section (the start of the first phase: a position before its velocity,
        # the amplitude of a forced oscillator) that changes along the families
        first = [n for n in res.unknowns if state_column(n, res) and n.startswith("x1_")]
        for name in first + [n for n in res.unknowns if state_column(n, res) and n not in first]:
            if not constant(physical_values(res, name)):
                y = name
                break
    return res.family, y, "%s_%s" % (y, res.family)


def figure_h_t(res, svg, written):
    xname, yname, name = main_diagram_axes(res)
    figure_of_columns(res, xname, yname, name, svg, written)


def figure_of_columns(res, xname, yname, name, svg, written, title=None):
    """One column over another for every branch: the main diagram, and any pair asked for (--x, --y)."""
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    drawn, sp_styles = projection(ax, res, xname, yname)
    if not drawn:
        ax.text(0.5, 0.5, "no branch points", transform=ax.transAxes, ha="center", va="center", color="0.4")
    focus_on_families(ax, res, xname, yname)
    ax.set_title((title or "%s over %s" % (column_symbol(yname), column_symbol(xname))) + ": " + model_title(res),
                 fontsize=10)
    place_legend(fig, ax, legend_handles(res, drawn, sp_styles, res.has_stable()))
    save(fig, res, name, svg, written)


def figure_words(res, svg, written):
    """A run across the words of an automaton: its physical orbits only, one colour per word, over the period
    and (where the model declares it) the mean forward speed; accepted changes of the phase sequence are
    stars at the orbit where the new word's family begins."""
    words = res.summary.get("words")
    if not isinstance(words, list) or len(words) < 2:
        return
    names = [str(w.get("name", "?")) for w in words if isinstance(w, dict)]
    word_of = {}
    for k, w in enumerate(words):
        for i in (w.get("branches") or []) if isinstance(w, dict) else []:
            word_of[i] = k
    has_speed = any(res.column(b, "speed") is not None for b in res.branches)
    xnames = ["T", "speed"] if has_speed else ["T"]
    fig, axes = plt.subplots(1, len(xnames), figsize=(6.0 * len(xnames), 4.4), squeeze=False)
    drawn = set()
    for b in res.branches:
        k = word_of.get(b["id"])
        phys = b["table"].num("physical")
        if k is None or phys is None:
            continue
        for ax, xname in zip(axes[0], xnames):
            xs, ys = res.column(b, xname), res.column(b, res.family)
            if xs is None or ys is None:
                continue
            pts = [(x, y) for x, y, p in zip(xs, ys, phys) if p == 1 and finite(x, y)]
            if pts:
                ax.plot([x for x, _ in pts], [y for _, y in pts], ".", ms=3.5, color=OKABE_ITO[k % len(OKABE_ITO)],
                        label=names[k] if k not in drawn else None)
                drawn.add(k)
    by_id = {b["id"]: b for b in res.branches}
    for change in res.summary.get("word_changes") or []:
        if not isinstance(change, dict) or not change.get("accepted") or not change.get("to_branches"):
            continue
        b = by_id.get(change["to_branches"][0])
        if b is None:
            continue
        for ax, xname in zip(axes[0], xnames):
            xs, ys = res.column(b, xname), res.column(b, res.family)
            if xs and ys and finite(xs[0], ys[0]):
                ax.plot(xs[0], ys[0], "*", ms=11, color="k", zorder=5)
    for ax, xname in zip(axes[0], xnames):
        ax.set_xlabel(axis_label(xname) if xname == "T" else "mean forward speed", fontsize=9)
        ax.set_ylabel(axis_label(res.family), fontsize=9)
        ax.grid(alpha=0.3)
    axes[0][0].set_title("physical orbits by phase sequence: " + model_title(res), fontsize=10)
    if drawn:
        axes[0][0].legend(fontsize=8, frameon=False, title="word (* a change of the phase sequence)",
                           title_fontsize=8)
    save(fig, res, "words", svg, written)


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
        xs, ys, zs = res.column(b, "T"), res.column(b, "xi"), res.column(b, res.family)
        if xs is None or ys is None or zs is None:
            continue
        t = b["table"]
        how = plot_runs(ax, xs, ys, t.num("physical"), t.num("stable") if stable else None, b["colour"], zs=zs)
        if how:
            drawn.append(dict(b, label=b["label"] + ("; a point here" if how == "point" else "")))
    sp_styles = draw_special_points(ax, res, "T", "xi", zname=res.family)
    ax.set_xlabel(axis_label("T"), fontsize=8)
    ax.set_ylabel(axis_label("xi"), fontsize=8)
    ax.set_zlabel(axis_label(res.family), fontsize=8)
    ax.tick_params(labelsize=7)
    ax.view_init(elev=22, azim=-60)
    ax.set_title(r"$\bar{H}$ over $T$ and $\xi$: " + model_title(res), fontsize=10)
    handles = legend_handles(res, drawn, sp_styles, stable)
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.08, 1.0), fontsize=8, frameon=False)
    save(fig, res, "H_T_xi", svg, written)


def data_range(res, name):
    vals = []
    for b in res.branches:
        col = res.column(b, name)
        if col:
            vals.extend(v for v in col if finite(v))
    return (min(vals), max(vals)) if vals else (0.0, 1.0)


# Open markers that tell the second, third, ... y column of a figure apart from the first (drawn as lines).
SERIES_MARKERS = [("o", "open circles"), ("s", "open squares"), ("^", "open triangles"), ("D", "open diamonds"),
                  ("v", "open down-triangles")]


def zoom_limits(res, points, xname, ynames):
    """Axis limits enclosing the special points, padded by 30 % of their spread (at least 5 % of the data)."""
    limits = []
    for names in ([xname], ynames):
        vals = [v for sp in points for v in (res.sp_value(sp, n) for n in names) if finite(v)]
        lo, hi = min(vals), max(vals)
        full_lo, full_hi = min(data_range(res, n)[0] for n in names), max(data_range(res, n)[1] for n in names)
        full = max(full_hi - full_lo, 1e-9)
        pad = max(0.3 * (hi - lo), 0.05 * full)
        limits.append((lo - pad, hi + pad))
    return limits


def figure_declared(res, spec, svg, written):
    """A figure the presentation declares: its y columns over its x column for every branch.

    Drawn like H_T.png (physical parts solid, the rest dashed, special points marked where they have the
    columns).  All y columns share one axes, so that related columns (the durations of the phases, say)
    compare directly; the first is drawn as lines, each further one also with open markers of its own
    shape.  With "zoom" the limits enclose the special points (other than the start), where a diagram's
    structure is too small to see at full scale; without special points the figure is skipped."""
    xname = spec["x"]

    def present(name):
        return any(res.column(b, name) is not None for b in res.branches)

    if not present(xname):
        warn("%s skipped: no branch file has the column '%s'" % (spec["file"], xname))
        return
    missing = [y for y in spec["y"] if not present(y)]
    ynames = [y for y in spec["y"] if y not in missing]
    if not ynames:
        warn("%s skipped: no branch file has the column%s %s" % (
            spec["file"], "s" if len(missing) > 1 else "", ", ".join("'%s'" % y for y in missing)))
        return
    if missing:
        warn("%s: no branch file has the column%s %s; drawn without" % (
            spec["file"], "s" if len(missing) > 1 else "", ", ".join("'%s'" % y for y in missing)))
    sp_filter = None
    if spec["zoom"]:
        interesting = [sp for sp in res.special_points if sp.get("type") != "start"
                       and finite(res.sp_value(sp, xname), res.sp_value(sp, ynames[0]))]
        if not interesting:
            warn("%s skipped: no special points to zoom on" % spec["file"])
            return
        ids = set(id(sp) for sp in interesting)
        sp_filter = lambda sp: id(sp) in ids  # noqa: E731

    fig, ax = plt.subplots(figsize=(7.0, 4.8))
    drawn, sp_styles = projection(ax, res, xname, ynames[0], sp_filter=sp_filter)
    stable = res.has_stable()
    extra = []
    for k, yname in enumerate(ynames[1:]):
        marker, words = SERIES_MARKERS[k % len(SERIES_MARKERS)]
        for b in res.branches:
            xs, ys = res.column(b, xname), res.column(b, yname)
            if xs is None or ys is None:
                continue
            t = b["table"]
            plot_runs(ax, xs, ys, t.num("physical"), t.num("stable") if stable else None, b["colour"])
            pts = [(x, y) for x, y in zip(xs, ys) if finite(x, y)]
            every = max(1, len(pts) // 12)
            if pts:
                ax.plot(*zip(*pts[::every]), ls="none", marker=marker, ms=4.5, mfc="white", mec=b["colour"],
                        mew=1.1, zorder=4)
        sp_styles.update(draw_special_points(ax, res, xname, yname, annotate=False, only=sp_filter))
        extra.append(Line2D([], [], color="0.2", lw=1.8, marker=marker, mfc="white", ms=4.5,
                            label="%s (%s)" % (column_symbol(yname), words)))
    if extra:
        extra.insert(0, Line2D([], [], color="0.2", lw=1.8,
                               label="%s (line)" % column_symbol(ynames[0])))
    ax.set_xlabel(axis_label(xname, res))
    ax.set_ylabel(axis_label_of(ynames, res))
    if len(ynames) == 1 and " over " in spec["title"]:  # the model's own words for its quantity
        ax.set_ylabel(spec["title"].split(" over ")[0] + "  (%s)" % ynames[0])
    if spec["zoom"]:
        (x0, x1), (y0, y1) = zoom_limits(res, interesting, xname, ynames)
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
    else:
        focus_on_families(ax, res, xname, ynames[0])
        # a column through zero (a duration, a velocity) changes its meaning there: mark the zero
        lo, hi = data_range(res, xname)
        if lo < 0 < hi:
            ax.axvline(0.0, color="0.6", lw=0.8, zorder=1)
        lo = min(data_range(res, y)[0] for y in ynames)
        hi = max(data_range(res, y)[1] for y in ynames)
        if lo < 0 < hi:
            ax.axhline(0.0, color="0.6", lw=0.8, zorder=1)
    head = spec["title"] or "%s over %s" % (", ".join(ynames), xname)
    ax.set_title(head + ": " + model_title(res), fontsize=10)
    place_legend(fig, ax, legend_handles(res, drawn, sp_styles, stable, extra))
    save(fig, res, spec["name"], svg, written)


# ----------------------------------------------------------------------------------------------------
# key frames
# ----------------------------------------------------------------------------------------------------

def load_orbit(path, phases):
    """Rows (t, segment, phase name, {point: (x, y)}) in time order: each sample's drawing points.

    A point is in a row when both its coordinates are numbers there (the writer leaves the cells empty
    where the sample's phase does not draw the point)."""
    table = Table(path)
    ts, segs = table.num("t"), table.num("segment")
    if ts is None or segs is None:
        raise ValueError("no t or segment column")
    columns = {}
    for c in table.columns:
        if c.startswith("draw.") and c.endswith(".x") and table.has(c[:-2] + ".y"):
            columns[c[5:-2]] = (table.num(c), table.num(c[:-2] + ".y"))
    if not columns:
        raise ValueError("no draw.<point>.x/.y columns (written before drawings were part of the results)")
    phase_of = table.text("phase")
    rows = []
    for r in range(table.n):
        if not finite(ts[r], segs[r]) or segs[r] < 1:
            continue
        seg = int(round(segs[r]))
        if phase_of is not None and phase_of[r]:
            phase = phase_of[r]
        else:  # no phase column: segment i runs phase (i-1) mod m
            phase = phases[(seg - 1) % len(phases)]["name"] if phases else ""
        points = {name: (xs[r], ys[r]) for name, (xs, ys) in columns.items() if finite(xs[r], ys[r])}
        rows.append((ts[r], seg, phase, points))
    # segments follow each other in time; sorting by segment first keeps a switch sample in its own
    # segment even when rounding puts its time a hair past the next segment's first sample
    rows.sort(key=lambda row: (row[1], row[0]))
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
    points = {k: (p[0] + w * (b[3][k][0] - p[0]), p[1] + w * (b[3][k][1] - p[1]))
              for k, p in a[3].items() if k in b[3]}
    return (t, a[1], a[2], points)


# Colours of the lines of the drawing's phases, in the order of summary["phases"].
PHASE_COLOURS = ["#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"]


class Drawing:
    """The presentation's drawing of the mechanism.

    shapes(frame, colour) gives the primitives of one sample in the model's coordinates: the lines of
    the sample's phase as polylines through its points (broken where a point is missing) in the phase's
    colour, their other points as small dots, and the masses as discs filled with `colour`."""

    def __init__(self, spec, phases):
        self.ground = spec["ground"]
        self.radius = spec["mass_radius"]
        self.phases = spec["phases"]
        known = [p["name"] for p in phases]
        order = [p for p in known if p in self.phases] + [p for p in self.phases if p not in known]
        self.colour = {p: PHASE_COLOURS[i % len(PHASE_COLOURS)] for i, p in enumerate(order)}
        self.order = order

    def shapes(self, frame, colour):
        t, seg, phase, points = frame
        spec = self.phases.get(phase)
        if spec is None:
            return []
        out = []
        line_colour = self.colour[phase]
        joints = {}
        for line in spec["lines"]:
            run = []
            for name in line + [None]:
                p = points.get(name) if name is not None else None
                if p is not None:
                    run.append(p)
                    if name not in spec["masses"]:
                        joints[name] = p
                    continue
                if len(run) >= 2:
                    out.append(("line", run, dict(color=line_colour, lw=2.0, solid_capstyle="round",
                                                  solid_joinstyle="round")))
                run = []
        for p in joints.values():
            out.append(("dot", p, dict(ms=3.5, color=line_colour)))
        for name in spec["masses"]:
            if name not in points:
                continue
            if self.radius > 0:
                out.append(("circle", points[name], self.radius, dict(fc=colour, ec="black", lw=0.8, zorder=5)))
            else:
                out.append(("dot", points[name], dict(ms=6, color=colour, mec="black", mew=0.8)))
        return out

    def masses(self, frame):
        spec = self.phases.get(frame[2])
        return [n for n in spec["masses"] if n in frame[3]] if spec else []

    def has_masses(self):
        return any(spec["masses"] for spec in self.phases.values())


def bbox_of(shapes):
    """(xmin, xmax, ymin, ymax) of the primitives, None when there are none."""
    xs, ys = [], []
    for s in shapes:
        if s[0] == "circle":
            (cx, cy), r = s[1], s[2]
            xs += [cx - r, cx + r]
            ys += [cy - r, cy + r]
        elif s[0] == "line":
            xs += [p[0] for p in s[1]]
            ys += [p[1] for p in s[1]]
        elif s[0] == "dot":
            xs.append(s[1][0])
            ys.append(s[1][1])
    xs = [v for v in xs if finite(v)]
    ys = [v for v in ys if finite(v)]
    if not xs or not ys:
        return None
    return (min(xs), max(xs), min(ys), max(ys))


def draw_shapes(ax, shapes, dx):
    for s in shapes:
        kind = s[0]
        if kind == "circle":
            (cx, cy), r, kw = s[1], s[2], dict(s[3])
            kw.setdefault("zorder", 4)
            ax.add_patch(Circle((cx + dx, cy), r, **kw))
        elif kind == "line":
            kw = dict(s[2])
            kw.setdefault("zorder", 4)
            ax.plot([p[0] + dx for p in s[1]], [p[1] for p in s[1]], **kw)
        elif kind == "dot":
            kw = dict(s[2])
            kw.setdefault("zorder", 6)
            ax.plot([s[1][0] + dx], [s[1][1]], marker="o", ls="none", **kw)


def drawing_scale(drawing, orbits):
    """Typical length of the drawing: the largest frame, or half the height the orbits sweep when that
    is larger (a lone mass is small but travels).  Margins, gaps and the scale bar follow it."""
    size, height = 0.0, 0.0
    for rows in orbits:
        ys = [0.0] if drawing.ground else []
        for row in rows:
            box = bbox_of(drawing.shapes(row, "k"))
            if box is not None:
                size = max(size, box[1] - box[0], box[3] - box[2])
                ys += [box[2], box[3]]
        if ys:
            height = max(height, max(ys) - min(ys))
    s = max(size, 0.5 * height)
    return s if finite(s) and s > 0 else 1.0


def orbit_layout(drawing, rows, n_frames, scale):
    """Frame times, frames, their boxes and horizontal offsets, and the dotted paths of the masses.

    Frames are placed left to right at equal spacing, wide enough that no two frames overlap whatever
    the mechanism's own horizontal motion (contained in the points) does between them; a path runs
    through the same spacing continuously in time."""
    t0, t1 = rows[0][0], rows[-1][0]
    period = t1 - t0
    times = [t0 + period * i / (n_frames - 1) for i in range(n_frames)]
    frames = [state_at(rows, t) for t in times]
    boxes = [bbox_of(drawing.shapes(f, "k")) for f in frames]
    widths = [b[1] - b[0] for b in boxes if b is not None] or [0.0]
    gap = 0.3 * scale
    spacing = max(max(widths) + gap, 0.75 * scale)
    for i in range(n_frames - 1):
        if boxes[i] is not None and boxes[i + 1] is not None:
            spacing = max(spacing, boxes[i][1] - boxes[i + 1][0] + gap)
    offsets = [spacing * i for i in range(n_frames)]
    paths = []  # polylines, broken at segment switches (a reset may move a point) and where a mass is absent
    current = {}
    seg_prev = None
    for row in rows:
        if row[1] != seg_prev:
            paths.extend(current.values())
            current, seg_prev = {}, row[1]
        frac = (row[0] - t0) / period if period > 0 else 0.0
        names = drawing.masses(row)
        for name in list(current):
            if name not in names:
                paths.append(current.pop(name))
        for name in names:
            x, y = row[3][name]
            current.setdefault(name, []).append((x + spacing * (n_frames - 1) * frac, y))
    paths.extend(current.values())
    return times, frames, boxes, offsets, [p for p in paths if len(p) >= 2]


def nice_length(s):
    """The largest 1, 2 or 5 times a power of ten not above s (the scale bar's length)."""
    unit = 10.0 ** math.floor(math.log10(s))
    for k in (5.0, 2.0, 1.0):
        if k * unit <= s * (1 + 1e-9):
            return k * unit
    return unit


def report_plane(res):
    """The regions of the curves' plane where families are physical and stable, computed by the library
    (summary.json's "regions", regions.h; folders written before 0.12.0: report.html's data), as {"regions": [...]},
    or {} without them."""
    if isinstance(res.summary.get("regions"), list):
        return {"regions": res.summary["regions"]}
    path = os.path.join(res.dir, "report.html")
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError:
        return {}
    start = text.find('<script id="study-data" type="application/json">')
    end = text.find("</script>", start)
    if start < 0 or end < 0:
        return {}
    try:
        data = json.loads(text[start + len('<script id="study-data" type="application/json">'):end])  # <\/ is JSON's /
    except ValueError:
        return {}
    plane = data.get("plane") if isinstance(data, dict) else None
    return plane if isinstance(plane, dict) else {}


CURVE_DASHES = {"fold": (0, (1.5, 1.5)), "branch-point": "-", "period-doubling": (0, (6, 2.5)),
                "neimark-sacker": (0, (6, 2, 1.5, 2)), "boundary": (0, (3, 1.5, 1, 1.5))}


def figure_curves(res, svg, written):
    """Two-parameter curves (summary "curves") in the (parameter, H) plane: each in the colour of the family
    whose special point it continues (boundaries dark grey), dashed by kind (fold dotted, branch point solid,
    period doubling dashed, Neimark-Sacker dash-dotted), labelled by that special point; codimension-two
    points as stars; the run's own parameter value as a dotted vertical line; shaded in the family's colour,
    the regions where it is physical (light) and stable (darker) that report.html's data holds."""
    entries = [c for c in (res.summary.get("curves") or []) if isinstance(c, dict) and isinstance(c.get("file"), str)]
    p = ((res.summary.get("options") or {}).get("curves") or {}).get("parameter")
    if not entries or not isinstance(p, str):
        return
    # The families' coordinate: H, or the run's free parameter (summaries before it was written: H).
    a = entries[0].get("coordinate") if isinstance(entries[0].get("coordinate"), str) else "H"
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    by_id = {sp.get("id"): sp for sp in res.special_points}
    for c in entries:
        with open(os.path.join(res.dir, c["file"]), newline="") as f:
            rows = list(csv.DictReader(f))
        xs, ys = [to_float(r.get(p)) for r in rows], [to_float(r.get(a)) for r in rows]
        kind = str(c.get("type"))
        sp = by_id.get(c.get("special_point"))
        branch = res.by_id.get(sp.get("branch")) if sp else None
        colour = branch["colour"] if branch and branch["family"] else "0.25"
        if kind == "boundary":
            label = "boundary %s" % c.get("name")
        else:
            label = "%s · %s%s" % (special_point_label(sp) if sp else "?%s" % c.get("special_point"), kind,
                                   " (%s)" % branch["family"] if branch and branch["family"] else "")
        ax.plot(xs, ys, color=colour, lw=1.8, ls=CURVE_DASHES.get(kind, "-"), label=label)
        for q in c.get("codim_two") or []:
            ax.plot([to_float(q.get(p))], [to_float(q.get(a))], "*", color="black", ms=8)
    # Regions, physical ones first: one fill per set of points (mirror images that coincide are one region,
    # named after both families, in the first one's colour).
    fills = {}
    for region in sorted(report_plane(res).get("regions") or [], key=lambda r: r.get("kind") == "stable"):
        poly = [q for q in region.get("polygon") or [] if isinstance(q, list) and len(q) == 2 and finite(*q)]
        family = region.get("family")
        colour = next((b["colour"] for b in res.branches if b["family"] == family), None)
        if len(poly) < 3 or not colour:
            continue
        key = (region.get("kind"), tuple(tuple(q) for q in poly))
        if key in fills:
            if family not in fills[key]["families"]:
                fills[key]["families"].append(family)
            continue
        fills[key] = {"families": [family], "colour": colour, "kind": region.get("kind"), "poly": poly}
    legend_regions = {}
    for f in fills.values():
        alpha = 0.35 if f["kind"] == "stable" else 0.12
        ax.fill([q[0] for q in f["poly"]], [q[1] for q in f["poly"]], color=f["colour"], lw=0, zorder=0, alpha=alpha)
        legend_regions.setdefault("%s: %s" % (" = ".join(f["families"]), f["kind"]), (f["colour"], alpha))
    value = res.parameters.get(p)
    if finite(value):
        ax.axvline(value, color="0.55", lw=0.8, ls=":", zorder=0)
    ax.set_xlabel(axis_label(p, res), fontsize=9)
    ax.set_ylabel(axis_label(a, res), fontsize=9)
    ax.grid(True, color="0.9", lw=0.6)
    ax.set_title(r"special points continued in $(%s, %s)$: " % (p, r"\bar{H}" if a == "H" else a) + model_title(res),
                 fontsize=10)
    handles = ax.get_legend_handles_labels()[0]
    from matplotlib.patches import Patch
    handles += [Patch(color=c, alpha=a, lw=0, label=name) for name, (c, a) in legend_regions.items()]
    ax.legend(handles=handles, fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False,
              borderaxespad=0.0)
    save(fig, res, "curves", svg, written)


def figure_keyframes(res, svg, written, n_frames=9):
    entries = [o for o in (res.summary.get("orbits") or []) if isinstance(o, dict)]
    if not entries:
        return
    spec = res.presentation.get("drawing")
    if not spec or not spec["phases"]:
        warn("the presentation has no drawing; keyframes.png skipped")
        return
    drawing = Drawing(spec, res.phases)
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
            rows = load_orbit(path, res.phases)
        except (OSError, ValueError, csv.Error) as e:
            warn("skipping %s: %s" % (fname, e))
            continue
        if rows[-1][0] <= rows[0][0]:
            warn("skipping %s: zero duration" % fname)
            continue
        if not any(row[2] in drawing.phases for row in rows):
            warn("skipping %s: the drawing has none of its phases (%s)" % (
                fname, ", ".join(sorted(set(row[2] for row in rows)))))
            continue
        orbits.append((o, rows))
    if not orbits:
        return

    s = drawing_scale(drawing, [rows for _, rows in orbits])
    layouts = [orbit_layout(drawing, rows, n_frames, s) for _, rows in orbits]
    cmap = plt.get_cmap("Blues")
    limits = []
    for times, frames, boxes, offsets, paths in layouts:
        placed = [(b, dx) for b, dx in zip(boxes, offsets) if b is not None]
        path_pts = [p for path in paths for p in path]
        xs = [b[0] + dx for b, dx in placed] + [b[1] + dx for b, dx in placed] + [p[0] for p in path_pts]
        ys = [b[2] for b, _ in placed] + [b[3] for b, _ in placed] + [p[1] for p in path_pts]
        if drawing.ground:
            ys.append(0.0)
        if not xs:
            xs, ys = [0.0, offsets[-1]], [0.0, s]
        limits.append([min(xs) - 0.25 * s, max(xs) + 0.25 * s, min(ys) - 0.3 * s, max(ys) + 0.25 * s])
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
    bar = nice_length(s)
    for ax, (o, rows), (times, frames, boxes, offsets, paths), lim in zip(axes, orbits, layouts, limits):
        ax.set_xlim(lim[0], lim[1])
        ax.set_ylim(lim[2], lim[3])
        ax.set_aspect("equal", adjustable="box", anchor="W")
        if drawing.ground:
            ax.axhline(0.0, color="black", lw=1.2, zorder=1)
            ax.fill_between([lim[0], lim[1]], -0.08 * s, 0.0, facecolor="none", edgecolor="0.55",
                            hatch="////", lw=0.0, zorder=0)
        for path in paths:
            ax.plot(*zip(*path), color="0.6", lw=0.8, ls=":", zorder=1)
        n = len(frames)
        # time labels under the ground, or under the lowest frame when there is no ground
        bottoms = [b[2] for b in boxes if b is not None]
        label_y = (0.0 if drawing.ground or not bottoms else min(bottoms)) - 0.11 * s
        for i, (t, frame, box, dx) in enumerate(zip(times, frames, boxes, offsets)):
            colour = cmap(0.35 + 0.55 * i / max(n - 1, 1))
            draw_shapes(ax, drawing.shapes(frame, colour), dx)
            cx = 0.5 * (box[0] + box[1]) if box is not None else 0.0
            ax.text(cx + dx, label_y, "t=%.2f" % t, ha="center", va="top", fontsize=7, color="0.3")
        label = str(o.get("label") or "orbit")
        H, T = to_float(o.get("H")), to_float(o.get("T"))
        if not finite(T):
            T = rows[-1][0] - rows[0][0]
        title = label
        if finite(H):
            title += r",  $\bar{H}=%.4g%s$" % (H, r"\ m_\mathrm{o} g l_\mathrm{o}" if UNITS["on"] else "")
        title += r",  $T=%.4g%s$" % (T, r"\ \sqrt{l_\mathrm{o}/g}" if UNITS["on"] else "")
        if "branch" in o:
            title += "  (branch %s)" % o.get("branch")
        ax.set_title(title, fontsize=9.5, loc="left")
        ax.set_axis_off()
        # scale bar: a round length in the model's unit
        x0 = lim[1] - 0.05 * s - bar
        ax.plot([x0, x0 + bar], [lim[3] - 0.12 * s] * 2, color="black", lw=1.5)
        ax.text(x0 + 0.5 * bar, lim[3] - 0.1 * s, "%g" % bar, ha="center", va="bottom", fontsize=8)
    notes = [Line2D([], [], color=drawing.colour[p], lw=2.0, label=p) for p in drawing.order
             if drawing.phases[p]["lines"]]
    if drawing.has_masses():
        notes.append(Line2D([], [], marker="o", ls="none", ms=6, mfc=cmap(0.6), mec="black", mew=0.8,
                            label="mass (darker: later)"))
        notes.append(Line2D([], [], color="0.6", lw=0.8, ls=":",
                            label="path of the masses (time runs left to right)"))
    if notes:
        fig.legend(handles=notes, loc="lower left", ncol=len(notes), fontsize=8, frameon=False,
                   bbox_to_anchor=(left_in / width_in, 0.0))
    fig.suptitle("Key frames, %s" % model_title(res), fontsize=10.5, x=left_in / width_in,
                 y=1.0 - 0.12 / height_in, ha="left", va="top")
    save(fig, res, "keyframes", svg, written)


# ----------------------------------------------------------------------------------------------------
# main
# ----------------------------------------------------------------------------------------------------

def parse_args(argv):
    parser = argparse.ArgumentParser(prog="hybridcont_plot.py",
                                     description="Figures from the results folder of 'hybridcont run'.")
    parser.add_argument("results_dir", help="folder with summary.json and the branch/orbit CSV files")
    parser.add_argument("--svg", action="store_true", help="also write every figure as SVG")
    parser.add_argument("--pdf", action="store_true", help="also write every figure as PDF")
    parser.add_argument("--all", action="store_true",
                        help="label the special points of every branch and show every branch whole "
                             "(by default the view encloses the physical families)")
    parser.add_argument("--x", metavar="COLUMN", help="with --y: draw only this column over --x's")
    parser.add_argument("--y", metavar="COLUMN", help="with --x: the column on the vertical axis")
    parser.add_argument("--frames", type=int, default=9,
                        help="key frames per orbit, equally spaced from t = 0 to T (2..16, default 9)")
    args = parser.parse_args(argv)
    if not 2 <= args.frames <= 16:
        parser.error("--frames must be between 2 and 16")
    if (args.x is None) != (args.y is None):
        parser.error("--x and --y go together (the two columns of one diagram)")
    return args


def check_columns(res, names):
    """Exit-2 error naming the column and the ones there are, when no branch has it."""
    known = set()
    for b in res.branches:
        if b["table"] is not None:
            known.update(b["table"].columns)
    for name in names:
        if name not in known:
            shown = sorted(c for c in known if c not in ("index", "classification", "stability"))
            raise PlotError("no branch file in %s has a column '%s'; the columns are: %s"
                            % (res.dir, name, ", ".join(shown)))


def main(argv):
    args = parse_args(argv)
    try:
        res = Results(args.results_dir)
    except PlotError as e:
        print("hybridcont_plot: error: %s" % e, file=sys.stderr)
        return 2
    except (TypeError, ValueError, AttributeError, KeyError) as e:  # a field of a type no check foresaw
        print("hybridcont_plot: error: %s is malformed: %s: %s" % (
            os.path.join(args.results_dir, "summary.json"), type(e).__name__, e), file=sys.stderr)
        return 2
    FIGURE_OPTIONS["all"] = args.all
    FIGURE_OPTIONS["formats"] = ["png"] + (["svg"] if args.svg else []) + (["pdf"] if args.pdf else [])
    if args.x is not None:
        try:
            check_columns(res, [args.x, args.y])
        except PlotError as e:
            print("hybridcont_plot: error: %s" % e, file=sys.stderr)
            return 2
    import_matplotlib()
    if args.x is not None:
        written = []
        figure_of_columns(res, args.x, args.y, "%s_%s" % (args.y, args.x), False, written)
        for path in written:
            print(path)
        return 0
    main_name = main_diagram_axes(res)[2]
    jobs = [(main_name, lambda w: figure_h_t(res, False, w))]
    if has_nonzero_xi(res):
        jobs.append(("H_T_xi", lambda w: figure_h_t_xi(res, args.svg, w)))
    jobs.append(("curves", lambda w: figure_curves(res, args.svg, w)))
    jobs.append(("words", lambda w: figure_words(res, args.svg, w)))
    if res.presentation is None:
        warn("%s has no 'presentation' (written by an older hybridcont): only the generic figures are drawn"
             % res.summary_path)
    else:
        names = set((main_name, "H_T_xi", "keyframes", "curves", "words"))
        for spec in res.presentation["figures"]:
            if spec["name"] in names:
                warn("%s is declared twice or would overwrite a generic figure; skipped" % spec["file"])
                continue
            names.add(spec["name"])
            jobs.append((spec["name"], lambda w, spec=spec: figure_declared(res, spec, args.svg, w)))
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
else:
    import_matplotlib()  # imported as a module (tests): its drawing helpers are ready to use
