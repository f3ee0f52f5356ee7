"""sweep-report.html: the sweep's maps to pan, zoom and hover, self-contained."""
import json
import os
import re

import pandas as pd

from .grid import read_definition
from .maps import MAP_CLASSES, curve_lines, map_classes


def write_report(out):
    """sweep-report.html: one self-contained page (Plotly.js inlined, nothing fetched) with the grid coloured
    per family by MAP_CLASSES or by the ends of its ranges, and each grid point's row on a click. Returns its
    path, or None (with a warning) when the package has no Plotly.js (built without npm)."""
    import warnings
    from .. import _hybridcont as native
    from .. import _paths
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
        template = f.read()
    with open(plotly, encoding="utf-8") as f:
        library = inert(f.read())
    with open(os.path.join(_paths.REPORT, "sweep.js"), encoding="utf-8") as f:
        viewer = inert(f.read())
    # The data's "<" as \u003c (the same string to JSON and JavaScript): a family named "<!--<script>" cannot open
    # an HTML comment or element inside the inline script.
    inserted = {"/*HYBRIDCONT_PLOTLY*/": library,
                "/*HYBRIDCONT_DATA*/": json.dumps(data, allow_nan=False).replace("<", "\\u003c"),
                "/*HYBRIDCONT_VIEWER*/": viewer}
    # Each marker found in the template before anything is inserted: text inserted cannot be taken for one.
    at = sorted((template.index(marker), marker) for marker in inserted)
    parts, end = [], 0
    for position, marker in at:
        parts += [template[end:position], inserted[marker]]
        end = position + len(marker)
    page = "".join(parts) + template[end:]
    path = os.path.join(out, "sweep-report.html")
    try:
        with open(path + ".tmp", "w", encoding="utf-8") as f:
            f.write(page)
        os.replace(path + ".tmp", path)
    except OSError:
        if os.path.exists(path + ".tmp"):
            os.remove(path + ".tmp")
        raise
    return path
