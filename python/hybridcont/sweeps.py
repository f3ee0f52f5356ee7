"""Sweeps: a study at every point of a parameter grid, on Dask, that survives a killed worker and resumes.

    import hybridcont as hc
    table = hc.sweep("slip", grid={"k": (10, 160, 8), "w2": (2, 10, 8)}, out="results/slip-map")
    table.query("family == 'hopping in place' and stable")     # where hopping in place has a stable range

    hybridcont sweep slip --grid k=10:160:8 --grid w2=2:10:8 --out results/slip-map [--scheduler tcp://...]

Every grid point is one task: the study of the model with the grid's parameters set (every option of
``hybridcont run`` applies to each), run by a Dask worker on one thread, its results folder saved under
``<out>/points/<id>/`` and its families summarized as rows of the tidy table ``<out>/table.csv``: one row per
grid point and family (the grid's parameters by name, the family, whether it exists there, is physical
somewhere, is stable somewhere, its physical and stable ranges, its located special points).

Where it runs: a local cluster of one single-threaded worker process per core by default; ``scheduler=``
(``--scheduler tcp://HOST:PORT``) an existing Dask cluster of many machines (a SLURM or PBS user starts one
with dask-jobqueue and passes its address; the workers need the package and a shared ``out`` folder).

Nothing lost, nothing twice. A task writes its study into a folder of its own and renames it to
``points/<id>`` when complete (atomic on one file system); a second copy of a task (Dask re-runs the tasks of
a worker that died) finds the folder there and keeps it. The table is assembled from the folders, so each
grid point is in it exactly once. ``resume=True`` (``--resume``) skips the grid points whose folder is
complete and computes the rest; the sweep's definition (``<out>/sweep.json``) must be the same.

Strategies (the table's ``strategy`` column says which one each grid point took):
  ``explore``    (the default) every grid point explored whole from the model's starts.
  ``continue``   the grid is covered breadth-first from the point nearest the model's own parameters, each
                 point after a neighbour one step closer (Dask runs a task once its neighbour's is done), whose
                 families it continues: its study leaves out the half-branches whose counterparts at the
                 neighbour led to no family (``families_of``, src/study/stages/family_guide.h). The SLIP's exploration
                 is 23 half-branches, its families' 5. Where a family of the neighbour is not found, the grid
                 point is explored whole instead ("explore (a family of 3_4 not continued)"); so is the first
                 grid point, and a point whose neighbour's study did not complete (stopped at max_branches: it
                 never followed some branches) or lacks a family of `families` ("explore (3_4 did not
                 complete)").
                 What it cannot see: a branch that had no physical orbit at the neighbour and has some here (the
                 guide left it out). Over the SLIP's (k, w2) plane its table is the whole explorations' to the last
                 bit; over the bipedal model's (k, beta) plane, at 5 of 64 grid points walking's stable range began
                 later than the whole exploration says (a stable walking branch the guide had seen without
                 physical orbits). Not the default for that reason: a model's maps are checked against
                 ``explore`` on a coarse grid before ``continue`` is trusted on a fine one.
A model file whose starts are guesses (orbits given by their unknowns) has them replaced, in either strategy, by
the orbits its neighbour's study found nearest to them (same word, same level H), corrected there by Newton: a
continuation of the starts in the grid's parameters (the grid is then covered breadth-first in either
strategy). The bipedal model's walking guess, written for k = 25.5, fails at k = 17.9, beta = 0.30; from its
neighbours' orbits it walks there.
"""
import argparse
import contextlib
import itertools
import json
import os
import re
import shutil
import sys
import time
import uuid

import numpy as np
import pandas as pd

SWEEP_FORMAT = 1


def grid_values(spec):
    """{name: (start, stop, count)} or {name: [values]} as {name: [values]} (linspace for a triple)."""
    out = {}
    for name, values in spec.items():
        if isinstance(values, tuple) and len(values) == 3:
            start, stop, count = values
            if int(count) != count or count < 1:
                raise ValueError("grid %s: the count must be a positive whole number, got %r" % (name, count))
            out[name] = [float(v) for v in np.linspace(float(start), float(stop), int(count))]
        else:
            vals = [float(v) for v in values]
            if not vals:
                raise ValueError("grid %s: no values" % name)
            out[name] = vals
    if not out:
        raise ValueError("sweep: the grid has no parameter")
    return out


def grid_points(values):
    """[(id, {name: value})] in row-major order; id "i_j" holds the indices along each grid parameter."""
    names = list(values)
    points = []
    for index in itertools.product(*(range(len(values[n])) for n in names)):
        points.append(("_".join(str(i) for i in index), {n: values[n][i] for n, i in zip(names, index)}))
    return points


def _intervals_text(intervals):
    """"1.2..1.4;1.6..1.9": a family's disjoint intervals, in full precision."""
    return ";".join("%.17g..%.17g" % (a, b) for a, b in intervals)


def family_rows(study, point_id, values, families=None):
    """The tidy rows of one grid point: one per family of its study (of `families` only, when given), from the
    study's own fold of its branches' ranges (Study.families: the numbers its one-screen answer prints).
    physical_from/to and stable_from/to are the first start and the last end; physical_ranges and
    stable_ranges list every disjoint interval, so a gap inside is never called physical or stable."""
    names = [f for f in (study.summary.get("presentation") or {}).get("families") or []]
    special = study.special_points.set_index("label") if len(study.special_points) else None
    found = {}
    for r in study.families.itertuples(index=False):
        if r.family not in names:
            names.append(r.family)
        row = found.setdefault(r.family, {"physical": [], "stable": [], "special_points": list(r.special_points)})
        row[r.kind].append((r[3], r[4]))  # from, to
    if families:
        names = list(families)
    rows = []
    for family in names:
        f = found.get(family)
        labels = []
        for label in (f["special_points"] if f else []):
            at = special.loc[label, "H"] if special is not None and label in special.index else None
            labels.append(label + ("@%.10g" % at if at is not None and not pd.isna(at) else ""))
        row = dict(values)
        row.update({"point": point_id, "family": family, "exists": f is not None,
                    "physical": bool(f and f["physical"]), "stable": bool(f and f["stable"]),
                    "physical_from": f["physical"][0][0] if f and f["physical"] else np.nan,
                    "physical_to": f["physical"][-1][1] if f and f["physical"] else np.nan,
                    "stable_from": f["stable"][0][0] if f and f["stable"] else np.nan,
                    "stable_to": f["stable"][-1][1] if f and f["stable"] else np.nan,
                    "physical_ranges": _intervals_text(f["physical"]) if f else "",
                    "stable_ranges": _intervals_text(f["stable"]) if f else "",
                    "special_points": ";".join(sorted(labels)),
                    "status": study.status})
        rows.append(row)
    if not rows:  # no family anywhere: the point is still in the table, once
        row = dict(values)
        row.update({"point": point_id, "family": "", "exists": False, "physical": False, "stable": False,
                    "physical_from": np.nan, "physical_to": np.nan, "stable_from": np.nan, "stable_to": np.nan,
                    "physical_ranges": "", "stable_ranges": "", "special_points": "", "status": study.status})
        rows.append(row)
    return rows


# ---- strategies (the module's docstring) -------------------------------------------------------------------
# A model file's guess starts are replaced by the orbits a neighbouring grid point's study found nearest to
# them (same word, same level H): a zeroth-order continuation in the grid's parameters, which keeps the starts
# converging far from the parameters they were written for. "continue" also traces only the half-branches that
# led to the neighbour's families (StudyOptions::families_of).

def model_document(model):
    """The parsed model file of a model (a path, a shipped model file's name, or a Model built from text), or
    None (a built-in model)."""
    import tomllib
    from . import _paths
    from .models import Model
    if isinstance(model, Model):
        if model.text is not None:
            return tomllib.loads(model.text)
        model = model.source
    if model is None:
        return None
    path = os.fspath(model)
    if not path.endswith(".toml"):
        shipped = os.path.join(_paths.MODELS, path + ".toml")
        from . import _hybridcont as native
        if path in native.builtin_model_names() or not os.path.exists(shipped):
            return None
        path = shipped
    elif not os.path.exists(path):
        path = os.path.join(_paths.MODELS, os.path.basename(path))
    with open(path, "rb") as f:
        return tomllib.load(f)


def guess_starts(document):
    """{index: start} of the model file's starts that are guesses with numeric values."""
    if not document or "start" not in document:
        return {}
    starts = document["start"] if isinstance(document["start"], list) else [document["start"]]
    return {i: s for i, s in enumerate(starts) if s.get("kind") == "guess" and isinstance(s.get("values"), dict)
            and all(isinstance(v, (int, float)) for v in s["values"].values())}


def with_starts(document, starts):
    """The model text of `document` with its guess starts' values replaced ({index: values})."""
    import copy
    import tomli_w
    doc = copy.deepcopy(document)
    listed = doc["start"] if isinstance(doc["start"], list) else [doc["start"]]
    for i, values in starts.items():
        listed[int(i)]["values"] = dict(values)
    return tomli_w.dumps(doc)


def orbits_near_starts(study, document, previous):
    """{index: values} for the next grid points: per guess start, the physical orbit of the study nearest to it
    (a branch of the start's word whose file has every unknown the start gives, the point nearest its H);
    `previous` where the study has none (it failed, or lost the family)."""
    found = dict(previous or {})
    summary = study.summary
    main_word = None
    for b in summary.get("branches") or []:
        main_word = main_word or b.get("word")
    points = study.points
    for i, start in guess_starts(document).items():
        word = start.get("word") or main_word
        keys = list(start["values"])
        ids = [b["id"] for b in summary.get("branches") or [] if b.get("word") == word and b.get("family")]
        if points.empty or not ids or not set(keys) <= set(points.columns):
            continue
        rows = points[points.branch.isin(ids) & (points.physical == 1)]
        if rows.empty:
            continue
        target = start["values"].get("H")
        row = rows.iloc[(rows["H"] - target).abs().argmin()] if target is not None else rows.iloc[0]
        values = {k: float(row[k]) for k in keys}
        if target is not None:
            values["H"] = float(target)  # the start's own level: the orbit is corrected there
        found[i] = values
    return found


def _failed_rows(point_id, values, message):
    row = dict(values)
    row.update({"point": point_id, "family": "", "exists": False, "physical": False, "stable": False,
                "physical_from": np.nan, "physical_to": np.nan, "stable_from": np.nan, "stable_to": np.nan,
                "physical_ranges": "", "stable_ranges": "", "special_points": "", "status": "failed: " + (message.splitlines() or ["(no message)"])[0][:300]})
    return [row]


def families_of_rows(rows):
    """The families a grid point's study found (sorted), or None where it has no study (it failed)."""
    if any(str(r["status"]).startswith("failed") for r in rows):
        return None
    return sorted({r["family"] for r in rows if r["exists"] and r["family"]})


def _study_at(m, point_id, values, options, out, document, starts, families_of, extra=None, families=None):
    """One study at a grid point into a new partial folder: (folder, rows, starts passed on, families)."""
    import hybridcont as hc
    partial = os.path.join(out, "points", ".partial-%s-%s" % (point_id, uuid.uuid4().hex))
    opts = dict(options)
    opts["set"] = dict(opts.get("set") or {}, **values)
    opts["threads"] = 1
    # A start that does not converge at this grid point is its status (start-failed), not the end of its study:
    # the model's starts in other words are still explored (the bipedal model's running where walking's fails).
    opts["start_must_converge"] = False
    for key, value in (extra or {}).items():  # the line's curves (sweep's `curves`) and their bound
        opts[key] = dict(opts.get(key) or {}, **value) if isinstance(value, dict) else value
    if families_of is not None:
        opts["families_of"] = families_of
        if families:
            opts["families"] = list(families)
    try:
        study = hc.run(m, out=partial, progress=False, report=False, **opts)  # the sweep has its own report
        if study.interrupted or study.status == "cancelled" or study.write_error:
            # Not this grid point's answer: left unfinished, so that a resume computes it again.
            raise RuntimeError("grid point %s: the study was %s" % (
                point_id, "stopped (%s)" % study.status if not study.write_error else "not written: " + study.write_error))
        rows = family_rows(study, point_id, values, families)
        if document is not None:
            starts = orbits_near_starts(study, document, starts)
    except ValueError as e:
        # The options and the grid's values were checked before the sweep began: what fails here is this grid
        # point's (a model whose setup is refused at these parameters, a guided study whose guide is refused):
        # its rows say so. (A start that does not converge is the study's status start-failed, not an error.)
        os.makedirs(partial, exist_ok=True)
        with open(os.path.join(partial, "error.txt"), "w") as f:
            f.write(str(e) + "\n")
        rows = _failed_rows(point_id, values, str(e))
    return partial, rows, starts


def run_grid_point(model, model_text, point_id, values, options, out, document=None, parent=None, guided=False,
                   extra=None, families=None):
    """One task: the study at one grid point, saved as <out>/points/<id>.

    parent: the result of the neighbouring grid point this one continues from ({"id", "starts", "families"}),
    or None. With `guided`, the study traces only the half-branches that led to its families there
    (StudyOptions::families_of: strategy "continue"); where a family of the neighbour is not found, the point
    is explored whole instead (the family may have ended, or its branch left another switch point). With a model
    file's `document`, its guess starts are the orbits the neighbour found. Returns {"id", "starts",
    "families"} for the next grid points. extra: options of this grid point's own (the curves of its line).
    families: the families to continue and tabulate (names; None: all).
    Runs in a worker process, the library on one thread."""
    import hybridcont as hc
    final = os.path.join(out, "points", point_id)
    if os.path.exists(os.path.join(final, "rows.json")):  # done before (resumed, or another copy of this task)
        return passed_on(final, document, parent)
    starts = dict((parent or {}).get("starts") or {})
    if document is not None and starts:
        model_text = with_starts(document, starts)
    m = hc.model(text=model_text) if model_text is not None else model
    from_orbits = " from %s's orbits" % parent["id"] if document is not None and starts else ""
    partial = None
    strategy = "explore" + from_orbits
    if guided and parent is not None:
        # A neighbour guides only where its study completed (one stopped at max_branches never followed some
        # branches) and found the families to continue (a family it lacks may be on a branch it would prune).
        missing = [f for f in (families or []) if f not in (parent.get("families") or [])]
        if not parent.get("completed"):
            strategy += " (%s did not complete)" % parent["id"]
        elif not parent.get("families") or missing:
            strategy += " (no %s at %s)" % (", ".join(missing) if missing else "family", parent["id"])
        else:
            partial, rows, found = _study_at(m, point_id, values, options, out, document, starts,
                                             os.path.join(out, "points", parent["id"]), extra, families)
            here = families_of_rows(rows)
            if here is None or not set(parent["families"]) <= set(here):
                # A family of the neighbour not found: it may have ended here, or its branch may now leave
                # another switch point than the guide's (or the guided study failed). The whole exploration
                # says which.
                shutil.rmtree(partial, ignore_errors=True)
                partial = None
                strategy += " (a family of %s not continued)" % parent["id"]
            else:
                strategy = "continue from %s" % parent["id"]
    if partial is None:
        partial, rows, found = _study_at(m, point_id, values, options, out, document, starts, None, extra, families)
    for row in rows:
        row["strategy"] = strategy
    with open(os.path.join(partial, "rows.json"), "w") as f:
        json.dump(rows, f)
    with open(os.path.join(partial, "starts.json"), "w") as f:
        json.dump({str(k): v for k, v in found.items()}, f)
    if os.path.isdir(final) and not os.path.exists(os.path.join(final, "rows.json")):
        shutil.rmtree(final, ignore_errors=True)  # a folder without its rows is no finished point
    try:
        os.rename(partial, final)  # atomic: the point appears whole, once
    except OSError:
        if not os.path.exists(os.path.join(final, "rows.json")):
            raise
        shutil.rmtree(partial, ignore_errors=True)  # another copy finished first: keep its folder
    return passed_on(final, document, parent)


ROW_KEYS = ("point", "family", "exists", "physical", "stable", "status")


def _read_json(path, what):
    """A sweep file read back (untrusted: a damaged or foreign file is a ValueError naming it)."""
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, UnicodeDecodeError, ValueError) as e:
        raise ValueError("'%s': not %s (%s)" % (path, what, e))


def read_rows(folder):
    """A finished grid point's rows (<folder>/rows.json), checked: a ValueError names the file and what is
    wrong, and says how to compute the point again."""
    path = os.path.join(folder, "rows.json")
    fix = "; remove %s to compute the grid point again" % folder
    try:
        rows = _read_json(path, "a grid point's rows")
    except ValueError as e:
        raise ValueError(str(e) + fix)
    if not isinstance(rows, list) or not rows:
        raise ValueError("'%s': not a grid point's rows (a non-empty list expected)%s" % (path, fix))
    for i, row in enumerate(rows):
        missing = [k for k in ROW_KEYS if not isinstance(row, dict) or k not in row]
        if missing:
            raise ValueError("'%s': row %d lacks '%s'%s" % (path, i, missing[0], fix))
        if row["point"] != os.path.basename(folder) or not isinstance(row["status"], str):
            raise ValueError("'%s': row %d is of grid point '%s', not '%s'%s"
                             % (path, i, row["point"], os.path.basename(folder), fix))
    return rows


def passed_on(folder, document, parent):
    """What a finished grid point passes on to its neighbours: {"id", "starts", "families", "completed"} (its
    study completed: it can guide theirs)."""
    rows = read_rows(folder)
    return {"id": os.path.basename(folder), "starts": _starts_of_folder(folder, document, parent),
            "families": families_of_rows(rows), "completed": all(r["status"] == "completed" for r in rows)}


def _starts_of_folder(folder, document, parent):
    """The orbits near the starts a finished grid point passes on (its starts.json)."""
    path = os.path.join(folder, "starts.json")
    if document is None or not os.path.exists(path):
        return dict((parent or {}).get("starts") or {})
    starts = _read_json(path, "the orbits a grid point passes on")
    try:
        return {int(k): {str(n): float(x) for n, x in v.items()} for k, v in starts.items()}
    except (AttributeError, TypeError, ValueError):
        raise ValueError("'%s': not the orbits a grid point passes on ({start: {unknown: value}} expected); "
                         "remove %s to compute the grid point again" % (path, folder))


def neighbour_tree(values, origin):
    """{point id: parent id or None}: the grid covered from the point nearest `origin` ({name: value}) outwards
    in breadth-first order, each point's parent a grid neighbour (one index apart along one parameter)."""
    names = list(values)
    shape = [len(values[n]) for n in names]

    def nearest(n):
        v = values[n]
        return min(range(len(v)), key=lambda i: abs(v[i] - origin.get(n, v[0])))
    root = tuple(nearest(n) for n in names)
    parent = {root: None}
    queue = [root]
    for index in queue:
        for axis in range(len(names)):
            for step in (-1, 1):
                j = list(index)
                j[axis] += step
                j = tuple(j)
                if 0 <= j[axis] < shape[axis] and j not in parent:
                    parent[j] = index
                    queue.append(j)
    key = lambda t: "_".join(str(i) for i in t)  # noqa: E731
    return {key(i): (key(p) if p is not None else None) for i, p in parent.items()}, [key(i) for i in queue]


def curve_points(values, parameter, own):
    """{point id: extra options}: on each line of the grid along `parameter`, the grid point nearest the model's
    own value (`own`) runs the curves in (H, parameter), bounded to the grid's range of it."""
    names = list(values)
    axis = names.index(parameter)
    v = values[parameter]
    at = min(range(len(v)), key=lambda i: abs(v[i] - (own if own is not None else v[0])))
    extra = {"curves": parameter, "bound": {parameter: (min(v), max(v))}}
    return {pid: extra for pid, _ in grid_points(values) if int(pid.split("_")[axis]) == at}


def _finite(x):
    """A float for JSON: None (a gap in a drawn line) for NaN or infinity."""
    x = float(x)
    return x if np.isfinite(x) else None


def curve_lines(out):
    """The two-parameter curves of a sweep run with ``curves=p``: {line: {"point", "curves"}}, a line named by
    its grid point ids' indices with p's replaced by "*" ("*_3"), each curve {"id", "type", "label", "family",
    "p", "H"} (the special point it continues, its family, and its points in (p, H))."""
    definition = read_definition(out)
    parameter = definition.get("curves")
    if not parameter:
        return {}
    axis = list(definition["grid"]).index(parameter)
    lines = {}
    from .study import load
    for pid in sorted(os.listdir(os.path.join(out, "points"))):
        folder = os.path.join(out, "points", pid)
        if pid.startswith(".") or not os.path.exists(os.path.join(folder, "summary.json")):
            continue
        head = _read_json(os.path.join(folder, "summary.json"), "a saved study's summary")
        if not isinstance(head, dict) or not head.get("curves"):
            continue  # a grid point without curves (all but one per line)
        study = load(folder)  # the library reads the folder back: a damaged one is a ValueError naming its file
        summary = study.summary
        special = {sp["id"]: sp for sp in summary.get("special_points") or []}
        families = {b["id"]: b.get("family") or "" for b in summary.get("branches") or []}
        frames = study.curves
        drawn = []
        for c in summary["curves"]:
            frame = frames[frames.curve == c["id"]] if len(frames) else frames
            if c.get("status") != "traced" or frame.empty or parameter not in frame.columns or "H" not in frame.columns:
                continue
            sp = special.get(c.get("special_point"), {})
            drawn.append({"id": c["id"], "type": c.get("type", ""),
                          "label": "%s%d" % (sp["type"], sp["id"]) if sp else c.get("name", ""),
                          "family": families.get(sp.get("branch"), "") if sp else "",
                          "p": [_finite(x) for x in frame[parameter]], "H": [_finite(x) for x in frame["H"]]})
        index = pid.split("_")
        index[axis] = "*"
        lines["_".join(index)] = {"point": pid, "curves": drawn}
    return lines


def _definition(model, grid, options, strategy):
    return {"format": SWEEP_FORMAT, "model": model, "grid": grid,
            "options": {k: v for k, v in sorted(options.items())}, "strategy": strategy}


@contextlib.contextmanager
def _main_script_hidden():
    """While the local cluster starts its worker processes: the main module without its file and spec, so that
    multiprocessing does not run the user's script again in each worker (spawn does, to find functions defined
    there; the tasks of a sweep are this module's). A script that sweeps at its top level, or one read from
    standard input, would otherwise start a cluster in every worker, or fail to start any."""
    main = sys.modules.get("__main__")
    saved = {k: main.__dict__[k] for k in ("__file__", "__spec__") if main is not None and k in main.__dict__}
    try:
        if main is not None:
            main.__dict__.pop("__file__", None)
            main.__dict__["__spec__"] = None
        yield
    finally:
        if main is not None:
            main.__dict__.pop("__spec__", None)
            main.__dict__.update(saved)


def _importing_main_script():
    """True while a process started by multiprocessing runs the parent's main script as ``__mp_main__``."""
    frame = sys._getframe(1)
    while frame is not None:
        if frame.f_globals.get("__name__") == "__mp_main__":
            return True
        frame = frame.f_back
    return False


def sweep(model, grid, out, scheduler=None, workers=None, resume=False, overwrite=False, progress=True,
          maps=True, strategy="explore", curves=None, families=None, **options):
    """Runs a study at every point of ``grid`` and returns the tidy table (also ``<out>/table.csv``).

    model: a name, a model file's path, or a Model (sent to the workers as its model text).
    grid: {parameter: (start, stop, count)} or {parameter: [values]}.
    scheduler: a Dask scheduler's address (tcp://HOST:PORT); None starts a local cluster of ``workers``
    single-threaded worker processes (default: one per core).
    resume: compute only the grid points whose folder is not complete (the same sweep, same options).
    maps: draw ``map-<family>.png`` (plot_maps) when the sweep is complete.
    strategy: "explore" (every grid point explored whole from the model's starts) or "continue" (each grid point
    continues its neighbour's families, explored whole where one is not found; the module's docstring says
    what it cannot see).
    curves: a grid parameter p: on every line of the grid along p, one grid point (the one nearest the model's
    own p) continues its families' special points in (H, p) over the grid's range of p (``run``'s curves), and
    the report draws them over the families' ranges along the line (``curve_lines``).
    families: the families to map (names, e.g. ["hopping in place"]): the table has their rows only, and with
    "continue" each grid point traces only the half-branches that led to them (the first is explored whole).
    options: those of ``hybridcont.run`` (set, until, bound, rtol, ...), for every grid point."""
    from .models import Model
    from dask.distributed import Client, LocalCluster, as_completed

    if scheduler is None and _importing_main_script():
        # A local cluster's worker process starts by importing the main script: a sweep at the script's top
        # level would start a cluster in every worker, which then never starts.
        raise RuntimeError("hybridcont.sweep: called while a worker process imports the script that sweeps; "
                           "call it under `if __name__ == \"__main__\":` (as every local Dask cluster needs)")

    values = grid_values(grid)
    points = grid_points(values)
    # Bad options end the sweep before anything runs (checked at the model's own parameters, the grid's names
    # against its parameters); what fails later at one grid point is that point's, in its rows.
    from .models import model as make_model
    m = model if isinstance(model, Model) else make_model(os.fspath(model))
    unknown = [n for n in values if n not in m.parameters]
    if unknown:
        raise ValueError("grid %s: model '%s' has no parameter '%s' (parameters: %s)"
                         % (unknown[0], m.name, unknown[0], ", ".join(m.parameters)))
    probe = m.with_parameters()  # each grid value within its parameter's range (bad input, not a failed point)
    for name, vals in values.items():
        for v in vals:
            try:
                probe.set_parameter(name, v)
            except ValueError as e:
                raise ValueError("grid %s: the value %.12g: %s" % (name, v, e))
    model_text = None
    if isinstance(model, Model):
        # Workers get the model as data (its text, or its name or path): a Model object holds the library's
        # model, which does not travel between processes. Its parameters travel as `set`.
        options = dict(options, set=dict(m.parameters, **(options.get("set") or {})))
        model_text = model.text
        model = None if model_text is not None else model.source
    if isinstance(model, os.PathLike):
        model = os.fspath(model)
    if isinstance(model, str) and model.endswith(".toml") and os.path.exists(model):
        model = os.path.abspath(model)  # the workers may run elsewhere (a str or a pathlib.Path alike)
    if model_text is None:
        from .study import check
        check(model, **dict(options, curves=curves) if curves is not None else options)
    model_name = m.name if model is None else os.fspath(model)
    out = os.path.abspath(os.fspath(out))
    document = model_document(model) if model_text is None else __import__("tomllib").loads(model_text)
    if not guess_starts(document):
        document = None  # nothing to carry from a neighbour: every grid point explores from the model's starts
    families = [families] if isinstance(families, str) else list(families) if families else None
    for i, name in enumerate(families or []):
        # A family is named by the model's rules, or (an automaton's family of another word) by its word.
        if name not in m.families and " > " not in name:
            raise ValueError("family '%s': not a family of model '%s' (families: %s; an automaton's family of "
                             "another word is named by its word, 'stance > flight > ...')"
                             % (name, m.name, ", ".join(m.families) or "none named"))
    if curves is not None and curves not in values:
        raise ValueError("curves '%s': not a parameter of the grid (%s)" % (curves, ", ".join(values)))
    if strategy not in ("continue", "explore"):
        raise ValueError("sweep: strategy '%s': expected 'continue' or 'explore'" % strategy)
    if strategy == "continue" and (options.get("free") or options.get("formulation", "time") != "time"):
        # A guide continues families in H, in the time-based formulation (StudyOptions::families_of).
        import warnings
        warnings.warn("sweep: strategy 'continue' needs families in H in the time-based formulation: every grid "
                      "point is explored whole", RuntimeWarning, stacklevel=2)
        strategy = "explore"
    guided = strategy == "continue"
    definition = _definition(model_name, values, options, strategy + (" (starts from the neighbours' orbits)"
                                                                       if document is not None else ""))
    if curves is not None:
        definition["curves"] = curves
    if families:
        definition["families"] = families
    definition_file = os.path.join(out, "sweep.json")
    if os.path.exists(definition_file) and overwrite and not resume:
        shutil.rmtree(out)  # replaced whole, whatever its files hold
    elif os.path.exists(definition_file):
        saved = read_definition(out)
        same = {k: v for k, v in saved.items() if k != "strategy"} == \
            {k: v for k, v in json.loads(json.dumps(definition)).items() if k != "strategy"}
        # 0.5.0 wrote "explore" or "neighbour" (every point whole, from its neighbour's orbits): both "explore".
        saved_strategy = str(saved.get("strategy", "explore")).split(" ")[0].replace("neighbour", "explore")
        if resume and same and saved_strategy != strategy:
            raise ValueError("resume '%s': the sweep there has strategy '%s'; resume it with strategy='%s' "
                             "(--strategy %s)" % (out, saved_strategy, saved_strategy, saved_strategy))
        if resume and not same:
            raise ValueError("resume '%s': the sweep there has another definition (model, grid or options); "
                             "resume it with its own" % out)
        if not resume:
            raise ValueError("sweep '%s': a sweep is there (resume=True continues it, overwrite=True replaces it)"
                             % out)
    elif resume:
        raise ValueError("resume '%s': no sweep there to resume" % out)
    if resume:  # the finished points' files are read back: checked before anything runs
        for pid, _ in points:
            folder = os.path.join(out, "points", pid)
            if os.path.exists(os.path.join(folder, "rows.json")):
                read_rows(folder)
                if document is not None:
                    _starts_of_folder(folder, document, None)
    os.makedirs(os.path.join(out, "points"), exist_ok=True)
    with open(definition_file + ".tmp", "w") as f:
        json.dump(definition, f, indent=1)
    os.replace(definition_file + ".tmp", definition_file)

    done = {pid for pid, _ in points if os.path.exists(os.path.join(out, "points", pid, "rows.json"))}
    todo = [(pid, v) for pid, v in points if pid not in done]
    # Partial folders of an interrupted sweep stay until this one ends: a task of it may still run on an
    # external cluster and write into its own (each task's name is unique), never into this sweep's.
    say = _progress(progress, len(points), len(points) - len(todo))
    # The order of the tasks: a tree over the grid from the point nearest the model's own parameters, each point
    # after the neighbour it continues from; none (any order) where nothing passes between grid points.
    tree_order = neighbour_tree(values, {n: m.parameters.get(n) for n in values}) \
        if guided or document is not None else None
    extras = curve_points(values, curves, m.parameters.get(curves)) if curves is not None else {}
    if todo:
        cluster = None
        if scheduler is None:
            with _main_script_hidden():
                cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                                       processes=True, dashboard_address=":0")
        client = Client(scheduler or cluster)
        try:
            # Task names of this sweep's own (a shared scheduler runs other sweeps: the same name would be
            # taken for the same task).
            from dask.base import tokenize
            prefix = "point-%s-" % tokenize(out, json.dumps(definition, sort_keys=True))[:12]
            futures = []
            if not tree_order:
                futures = [client.submit(run_grid_point, model, model_text, pid, v, options, out, None, None, False,
                                         extras.get(pid), families, key=prefix + pid, pure=False) for pid, v in todo]
            else:
                # Breadth-first from the point nearest the model's own parameters: each task gets its neighbour's
                # result (a future: Dask runs it after that one); finished points pass theirs from their folder.
                tree, order = tree_order
                by_id = dict(points)
                results = {}
                for pid in order:
                    parent = results.get(tree[pid]) if tree[pid] is not None else None
                    if pid in done:
                        results[pid] = passed_on(os.path.join(out, "points", pid), document, None)
                        continue
                    results[pid] = client.submit(run_grid_point, model, model_text, pid, by_id[pid], options, out,
                                                 document, parent, guided, extras.get(pid), families,
                                                 key=prefix + pid, pure=False)
                    futures.append(results[pid])
            for future in as_completed(futures):
                future.result()
                say()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    for stale in os.listdir(os.path.join(out, "points")):  # copies of tasks whose worker died
        if stale.startswith(".partial-"):
            shutil.rmtree(os.path.join(out, "points", stale), ignore_errors=True)
    say(done=True)
    table = assemble(out, points)
    write_report(out)
    if maps:
        try:
            plot_maps(out)
        except ImportError as e:  # matplotlib is the figures' (python3-matplotlib), not the sweep's
            import warnings
            warnings.warn("maps not drawn: %s" % e, RuntimeWarning, stacklevel=2)
    return table


def read_definition(out):
    """<out>/sweep.json, checked (a ValueError names the file)."""
    path = os.path.join(out, "sweep.json")
    definition = _read_json(path, "a sweep's definition")
    grid = definition.get("grid") if isinstance(definition, dict) else None
    if not isinstance(grid, dict) or not grid or not all(
            isinstance(v, list) and v and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
            for v in grid.values()):
        raise ValueError("'%s': not a sweep's definition (its grid: {parameter: [values]} expected)" % path)
    if not isinstance(definition.get("model"), str):
        raise ValueError("'%s': not a sweep's definition (its model's name expected)" % path)
    return definition


def assemble(out, points=None):
    """The tidy table of a sweep's folder (every complete grid point, once), written to <out>/table.csv."""
    if points is None:
        points = grid_points(read_definition(out)["grid"])
    rows = []
    for pid, _ in points:
        folder = os.path.join(out, "points", pid)
        if os.path.exists(os.path.join(folder, "rows.json")):
            rows.extend(read_rows(folder))
    table = pd.DataFrame(rows)
    table.to_csv(os.path.join(out, "table.csv.tmp"), index=False)
    os.replace(os.path.join(out, "table.csv.tmp"), os.path.join(out, "table.csv"))
    return table


# The classes of a grid point for one family, drawn from light to dark. Absent is said only where the study
# completed; a study that stopped at its limit (max-branches) may not have reached the family ("not found"),
# and one whose start did not converge at the grid point's parameters knows nothing of it ("study failed").
MAP_CLASSES = ["study failed (no start)", "not found (study stopped at its limit)", "absent",
               "exists, no physical orbit", "physical, not stable", "stable"]


def map_classes(table, family):
    """{point: class index} of one family over the grid (MAP_CLASSES)."""
    out = {}
    for r in table.drop_duplicates("point").itertuples():
        status = str(r.status)
        out[r.point] = 0 if status.startswith("failed") or status == "start-failed" else 2 if status == "completed" else 1
    rows = table[(table.family == family) & table.exists.astype(bool)]
    out.update({r.point: (5 if r.stable else 4 if r.physical else 3) for r in rows.itertuples()})
    return out


def plot_maps(out, formats=("png",)):
    """The maps of a sweep's folder: per family, where over the grid it exists, is physical and is stable
    (``map-<family>.png``; a 1-D grid as a strip); returns the paths written."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch
    definition = read_definition(out)
    grid = definition["grid"]
    names = list(grid)
    if len(names) > 2:
        import warnings
        warnings.warn("maps are drawn for grids of one or two parameters; this one has %d (table.csv has it all)"
                      % len(names), RuntimeWarning, stacklevel=2)
        return []
    table = pd.read_csv(os.path.join(out, "table.csv"), keep_default_na=False, dtype={"point": str})
    families = [f for f in dict.fromkeys(table.family) if f]
    palette = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#56B4E9", "#E69F00", "#000000"]
    lines = curve_lines(out) if definition.get("curves") else {}
    written = []
    for k, family in enumerate(families):
        classes = map_classes(table, family)
        colour = palette[k % len(palette)]
        shades = ["#f2c4c4", "#f3edc9", "white", "0.85", colour + "55", colour]
        cmap = ListedColormap(shades)
        x = grid[names[0]]
        y = grid[names[1]] if len(names) > 1 else [0.0]
        z = np.full((len(y), len(x)), np.nan)  # not computed (an unfinished sweep): blank
        for pid, c in classes.items():
            idx = [int(i) for i in pid.split("_")]
            z[idx[1] if len(names) > 1 else 0, idx[0]] = c
        fig, ax = plt.subplots(figsize=(6.2, 4.6 if len(names) > 1 else 1.8))
        edges = lambda v: np.concatenate([[v[0] - (v[1] - v[0]) / 2 if len(v) > 1 else v[0] - 0.5],  # noqa: E731
                                          (np.array(v[1:]) + np.array(v[:-1])) / 2 if len(v) > 1 else [],
                                          [v[-1] + (v[-1] - v[-2]) / 2 if len(v) > 1 else v[-1] + 0.5]])
        ax.pcolormesh(edges(x), edges(y), np.ma.masked_invalid(z), cmap=cmap, vmin=-0.5, vmax=5.5)
        ax.set_xlabel("parameter %s" % names[0])
        if len(names) > 1:
            ax.set_ylabel("parameter %s" % names[1])
        else:
            ax.set_yticks([])
        ax.set_title("%s: %s over %s" % (definition["model"], family, " and ".join(names[:2])), fontsize=10)
        ax.legend(handles=[Patch(facecolor=c, edgecolor="0.6", label=l) for c, l in zip(shades, MAP_CLASSES)],
                  loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8, frameon=False)
        slug = "".join(ch if ch.isalnum() else "-" for ch in family).strip("-")
        for ext in formats:
            path = os.path.join(out, "map-%s.%s" % (slug, ext))
            fig.savefig(path, dpi=160, bbox_inches="tight")
            written.append(path)
        plt.close(fig)
        # Where it is stable somewhere on a 2-D grid: the ends of its stable range in the continued coordinate.
        rows = table[(table.family == family) & (table.stable.astype(str) == "True")]
        if len(names) > 1 and len(rows):
            fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.2), sharey=True)
            for ax, column, what in zip(axes, ("stable_from", "stable_to"), ("from", "to")):
                z = np.full((len(y), len(x)), np.nan)
                for r in rows.itertuples():
                    i, j = (int(v) for v in r.point.split("_")[:2])
                    z[j, i] = float(getattr(r, column))
                mesh = ax.pcolormesh(edges(x), edges(y), np.ma.masked_invalid(z), cmap="viridis")
                fig.colorbar(mesh, ax=ax, label="stable %s" % what)
                ax.set_xlabel("parameter %s" % names[0])
                ax.set_title("%s: stable %s" % (family, what), fontsize=10)
            axes[0].set_ylabel("parameter %s" % names[1])
            for ext in formats:
                path = os.path.join(out, "map-%s-stable-range.%s" % (slug, ext))
                fig.savefig(path, dpi=160, bbox_inches="tight")
                written.append(path)
            plt.close(fig)
        if lines:
            written += _plot_plane(out, definition, table, family, colour, lines, formats, slug)
    return written


def _plot_plane(out, definition, table, family, colour, lines, formats, slug):
    """plane-<family>.png: the family's ranges in (p, H) along the grid line of the sweep's first curve point,
    the two-parameter curves over them (a sweep with curves = p)."""
    import matplotlib.pyplot as plt
    parameter = definition["curves"]
    names = list(definition["grid"])
    axis = names.index(parameter)
    key, line = next(iter(lines.items()))
    on_line = table[table.point.map(lambda pid: "_".join("*" if i == axis else v for i, v in enumerate(pid.split("_")))
                                    == key) & (table.family == family)]
    fig, ax = plt.subplots(figsize=(6.6, 4.4))
    for kind, width, alpha in (("physical", 2.5, 0.35), ("stable", 7, 1.0)):
        first = True
        for r in on_line.itertuples():
            a, b = getattr(r, kind + "_from"), getattr(r, kind + "_to")
            if a in ("", None) or b in ("", None) or pd.isna(a) or pd.isna(b):
                continue
            p = float(getattr(r, parameter))
            ax.plot([p, p], [float(a), float(b)], color=colour, lw=width, alpha=alpha, solid_capstyle="butt",
                    label="%s range" % kind if first else None)
            first = False
    dashes = {"period-doubling": "--", "neimark-sacker": "-.", "branch-point": ":", "fold": (0, (8, 3))}
    for c in line["curves"]:
        mine = c["family"] == family
        ax.plot(np.asarray(c["p"], dtype=float), np.asarray(c["H"], dtype=float), color="0.1" if mine else "0.6", lw=1.3 if mine else 0.9,
                linestyle=dashes.get(c["type"], "-"), label="%s curve of %s" % (c["type"], c["label"]))
    others = [n for n in names if n != parameter]
    where = ", ".join("%s = %.6g" % (n, float(on_line.iloc[0][n])) for n in others) if len(on_line) and others else ""
    ax.set_xlabel("parameter %s" % parameter)
    ax.set_ylabel("energy H")
    ax.set_title("%s: %s in (%s, H)%s" % (definition["model"], family, parameter, " at " + where if where else ""),
                 fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    written = []
    for ext in formats:
        path = os.path.join(out, "plane-%s.%s" % (slug, ext))
        fig.savefig(path, dpi=160, bbox_inches="tight")
        written.append(path)
    plt.close(fig)
    return written


def write_report(out):
    """sweep-report.html: one self-contained page (Plotly.js inlined, nothing fetched) with the grid coloured
    per family by MAP_CLASSES or by the ends of its ranges, and each grid point's row on a click. Returns its
    path, or None (with a warning) when the package has no Plotly.js (built without npm)."""
    import warnings
    from . import _hybridcont as native
    from . import _paths
    plotly = os.path.join(_paths.REPORT, "plotly-basic.min.js")
    if not os.path.exists(plotly):
        warnings.warn("sweep-report.html not written: %s is missing (built without npm)" % plotly, RuntimeWarning)
        return None
    definition = read_definition(out)
    table = pd.read_csv(os.path.join(out, "table.csv"), keep_default_na=False, dtype={"point": str})
    families = [f for f in dict.fromkeys(table.family) if f]
    points = []
    for pid, rows in table.groupby("point", sort=False):
        first = rows.iloc[0]
        entry = {"id": pid, "values": {n: float(first[n]) for n in definition["grid"]}, "status": str(first.status),
                 "strategy": str(first.get("strategy", "explore")), "families": {}}
        classes = {}
        for family in families:
            classes[family] = map_classes(rows, family).get(pid, 2)
        for family in families:
            f = rows[rows.family == family]
            item = {"class": int(classes[family])}
            if len(f):
                r = f.iloc[0]
                for key in ("physical_from", "physical_to", "stable_from", "stable_to"):
                    item[key] = float(r[key]) if r[key] not in ("", None) and not pd.isna(r[key]) else None
                for key in ("physical_ranges", "stable_ranges"):  # every disjoint interval
                    item[key] = str(r[key]) if key in r and not pd.isna(r[key]) else ""
                item["special_points"] = str(r.special_points)
            entry["families"][family] = item
        points.append(entry)
    data = {"model": definition["model"], "grid": definition["grid"], "strategy": definition["strategy"],
            "version": native.__version__, "classes": MAP_CLASSES, "families": families, "points": points}
    if definition.get("curves"):
        data["curves"] = {"parameter": definition["curves"], "lines": curve_lines(out)}

    def inert(text):  # "</script" (any case) would end the inline script early; "<\/" means the same to JS and JSON
        return re.sub(r"</(script)", r"<\\/\1", text, flags=re.IGNORECASE)
    with open(os.path.join(_paths.REPORT, "sweep.html"), encoding="utf-8") as f:
        page = f.read()
    with open(plotly, encoding="utf-8") as f:
        page = page.replace("/*HYBRIDCONT_PLOTLY*/", inert(f.read()), 1)
    page = page.replace("/*HYBRIDCONT_DATA*/", inert(json.dumps(data, allow_nan=False)), 1)
    with open(os.path.join(_paths.REPORT, "sweep.js"), encoding="utf-8") as f:
        page = page.replace("/*HYBRIDCONT_VIEWER*/", inert(f.read()), 1)
    path = os.path.join(out, "sweep-report.html")
    with open(path + ".tmp", "w", encoding="utf-8") as f:
        f.write(page)
    os.replace(path + ".tmp", path)
    return path


def _progress(progress, total, done):
    """A function to call after each grid point: done/total, rate, time left (tqdm where installed)."""
    start = time.perf_counter()
    state = {"done": done, "new": 0}
    if progress is False or progress is None:
        return lambda done=False: None
    try:
        from tqdm.auto import tqdm
        bar = tqdm(total=total, initial=done, unit=" points", desc="sweep")
    except ImportError:
        bar = None

    def say(done=False):
        if done:
            if bar is not None:
                bar.close()
            return
        state["done"] += 1
        state["new"] += 1
        if bar is not None:
            bar.update(1)
            return
        elapsed = time.perf_counter() - start
        rate = state["new"] / elapsed if elapsed > 0 else 0.0
        left = (total - state["done"]) / rate if rate > 0 else float("nan")
        print("sweep: %d/%d grid points, %.2f points/s, %.0f s left" % (state["done"], total, rate, left),
              file=sys.stderr)
    return say


def _parse_grid(text):
    name, _, spec = text.partition("=")
    parts = spec.split(":")
    if not name or len(parts) != 3:
        raise argparse.ArgumentTypeError("--grid '%s': expected NAME=START:STOP:COUNT" % text)
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise argparse.ArgumentTypeError("--grid '%s': START and STOP are numbers, COUNT a whole number" % text)
    if not (np.isfinite(start) and np.isfinite(stop)):
        raise argparse.ArgumentTypeError("--grid '%s': START and STOP must be finite" % text)
    return name, (start, stop, count)


def _parse_bound(text):
    """NAME=LO:HI (either side may be empty) as (name, (lo, hi)), None for an open side; checked by the library."""
    from . import _hybridcont as native
    try:
        name, lower, upper = native.parse_bound("--bound", text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e))
    return name, (None if np.isinf(lower) else lower, None if np.isinf(upper) else upper)


def _parse_pairs(text, option):
    """NAME=VALUE or NAME=V1,V2,... as [(name, value)], checked by the library as `hybridcont run` checks it."""
    from . import _hybridcont as native
    try:
        return native.parse_assignments(option, text)
    except ValueError as e:
        raise argparse.ArgumentTypeError(str(e))


def _parse_pair(text, option):
    pairs = _parse_pairs(text, option)
    if len(pairs) != 1:
        raise argparse.ArgumentTypeError("%s '%s': expected NAME=VALUE (one value)" % (option, text))
    return pairs[0]


def main(argv=None):
    """`hybridcont sweep` (the tool runs this module): the grid, where to run, and the options of `run`."""
    p = argparse.ArgumentParser(prog="hybridcont sweep", description="A study at every point of a parameter grid.")
    p.add_argument("model")
    p.add_argument("--grid", action="append", required=True, type=_parse_grid, help="NAME=START:STOP:COUNT")
    p.add_argument("--out", help="the sweep's folder (default results/MODEL-sweep)")
    p.add_argument("--scheduler", help="a Dask scheduler's address, tcp://HOST:PORT (default: a local cluster)")
    p.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    p.add_argument("--resume", action="store_true")
    p.add_argument("--overwrite", action="store_true")
    p.add_argument("--quiet", action="store_true")
    p.add_argument("--no-maps", action="store_true", help="draw no map figures")
    p.add_argument("--strategy", choices=("explore", "continue"), default="explore",
                   help="explore (the default): every grid point explored whole; continue: each grid point "
                        "continues its neighbour's families (faster; check it against explore on a coarse grid)")
    p.add_argument("--set", action="append", default=[], type=lambda t: _parse_pair(t, "--set"))
    p.add_argument("--until", action="append", default=[], type=lambda t: _parse_pair(t, "--until"))
    p.add_argument("--bound", action="append", default=[], type=_parse_bound, help="NAME=LO:HI")
    p.add_argument("--rtol", type=float)
    p.add_argument("--atol", type=float)
    p.add_argument("--max-branches", type=int)
    p.add_argument("--formulation", default="time")
    p.add_argument("--no-symmetry", action="store_true")
    p.add_argument("--family", action="append", dest="families",
                   help="map only this family (its name; repeatable): the table has its rows, each grid point "
                        "traces only what led to it")
    p.add_argument("--curves", help="a grid parameter P: on every grid line along P, one grid point continues its "
                                    "families' special points in (H, P); the report draws them over the ranges")
    p.add_argument("--monitor", action="append", default=[], type=lambda t: _parse_pairs(t, "--monitor"),
                   help="NAME=VALUE or NAME=V1,V2,...: locate where an observable takes the values (repeatable)")
    p.add_argument("--period-doubling", action="store_true")
    p.add_argument("--one-word", action="store_true")
    p.add_argument("--free", help="a parameter continued instead of H (with --fix; every grid point explored whole)")
    p.add_argument("--fix", type=lambda t: _parse_pair(t, "--fix"), help="NAME=VALUE held while --free varies")
    args = p.parse_args(argv)
    import warnings  # the command line says the sweep's warnings as notes, without Python's file and line
    warnings.showwarning = lambda message, *rest, **named: print("note: %s" % message, file=sys.stderr)
    monitors = {}
    for pairs in args.monitor:
        for name, value in pairs:
            monitors.setdefault(name, []).append(value)
    options = {"set": dict(args.set), "until": dict(args.until), "bound": dict(args.bound), "monitor": monitors,
               "rtol": args.rtol, "atol": args.atol, "max_branches": args.max_branches,
               "formulation": args.formulation, "no_symmetry": args.no_symmetry,
               "period_doubling": args.period_doubling, "one_word": args.one_word, "free": args.free,
               "fix": dict([args.fix]) if args.fix else None}
    options = {k: v for k, v in options.items() if not (v is None or v is False or (isinstance(v, dict) and not v))}
    out = args.out or os.path.join("results", os.path.basename(args.model).replace(".toml", "") + "-sweep")
    try:
        table = sweep(args.model, dict(args.grid), out, scheduler=args.scheduler, workers=args.workers,
                      resume=args.resume, overwrite=args.overwrite, progress=not args.quiet,
                      maps=not args.no_maps, strategy=args.strategy, curves=args.curves, families=args.families,
                      **options)
    except ValueError as e:
        print("error: %s" % e, file=sys.stderr)
        return 2
    except (RuntimeError, OSError) as e:  # a grid point's study stopped or not written (a full disk)
        print("error: %s\nthe grid points finished are kept in %s; --resume continues the sweep"
              % (e, os.path.abspath(out)), file=sys.stderr)
        return 1
    points = table["point"].nunique() if len(table) else 0
    print("%d grid points, %d rows: %s" % (points, len(table), os.path.join(os.path.abspath(out), "table.csv")))
    return 0


if __name__ == "__main__":
    sys.exit(main())
