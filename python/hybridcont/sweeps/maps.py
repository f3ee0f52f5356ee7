"""Maps of a sweep: each family's class over the grid (map-<family>.png), its stable range, and the
two-parameter curves over its ranges along grid lines."""
import os

import numpy as np
import pandas as pd

from .grid import read_definition


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
    from ..study import load
    for pid in sorted(os.listdir(os.path.join(out, "points"))):
        folder = os.path.join(out, "points", pid)
        if pid.startswith(".") or not os.path.exists(os.path.join(folder, "summary.json")):
            continue
        study = load(folder)  # the library reads the folder back: a damaged one is a ValueError naming its file
        frames = study.curves
        if frames.empty:
            continue  # a grid point without curves (all but one per line)
        special = study.special_points.set_index("id") if len(study.special_points) else None
        families = dict(zip(study.branches["id"], study.branches["family"]))
        drawn = []
        for curve_id, frame in frames.groupby("curve", sort=True):
            first = frame.iloc[0]
            if first["status"] != "traced" or parameter not in frame.columns or "H" not in frame.columns:
                continue
            sp = special.loc[first["special_point"]] if special is not None and first["special_point"] in special.index else None
            drawn.append({"id": int(curve_id), "type": first["type"],
                          "label": sp["label"] if sp is not None else first["name"],
                          "family": families.get(int(sp["branch"]), "") if sp is not None else "",
                          "p": [_finite(x) for x in frame[parameter]], "H": [_finite(x) for x in frame["H"]]})
        index = pid.split("_")
        index[axis] = "*"
        lines["_".join(index)] = {"point": pid, "curves": drawn}
    return lines


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
