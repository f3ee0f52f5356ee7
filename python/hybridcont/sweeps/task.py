"""One grid point's task: its study (guided by a neighbour's, or from the orbits a neighbour found nearest to
the model's starts), written into a folder of its own and renamed into place when complete."""
import json
import os
import shutil
import uuid

from .grid import _read_json
from .table import _failed_rows, families_of_rows, family_rows, read_rows


def model_document(model):
    """The parsed model file of a model (a path, a shipped model file's name, or a Model built from text), or
    None (a built-in model)."""
    import tomllib
    from .. import _paths
    from ..models import Model
    if isinstance(model, Model):
        if model.text is not None:
            return tomllib.loads(model.text)
        model = model.source
    if model is None:
        return None
    path = os.fspath(model)
    if not path.endswith(".toml"):
        shipped = os.path.join(_paths.MODELS, path + ".toml")
        from .. import _hybridcont as native
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
    branches = study.branches
    words = [w for w in branches["word"] if isinstance(w, str) and w]
    main_word = words[0] if words else None  # the study's own word: its first branch's (" > "-joined modes)
    points = study.points
    for i, start in guess_starts(document).items():
        word = start.get("word")
        word = " > ".join(word) if isinstance(word, list) else word or main_word
        keys = list(start["values"])
        ids = [int(b.id) for b in branches.itertuples() if b.word == word and b.family]
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
