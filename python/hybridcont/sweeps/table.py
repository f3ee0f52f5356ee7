"""The tidy table of a sweep: one row per grid point and family, from each grid point's study (its
one fold of the families' ranges, Study.families), read back from the grid points' folders and assembled."""
import os

import numpy as np
import pandas as pd

from .grid import _read_json, grid_points, read_definition


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


ROW_KEYS = ("point", "family", "exists", "physical", "stable", "status")


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
