"""Studies: ``hybridcont.run`` (what ``hybridcont run`` does, from Python) and the results as DataFrames.

    import hybridcont as hc
    study = hc.run("slip", until={"H": 1.8})      # every option of `hybridcont run`, as keyword arguments
    print(study)                                  # the one-screen answer
    study.special_points                          # DataFrame: label, type, branch, H, T, status, precision ...
    study.points                                  # every analysed point, one row each
    study.families                                # where each family is physical and stable
    pd4 = study.continue_from("PD4")              # the period-doubled family born at PD4
    study.save("results/slip"); hc.load("results/slip")

A study is the library's typed result (study.h) and its results folder (docs/results-format.md), the one
serialization of it. ``families``, ``special_points``, ``branches``, ``word_changes``, ``curves`` and ``points`` are
the typed result's (of the run in memory, or of the folder read back by the library's LoadStudy: the same rows);
``orbits`` are the folder's orbit files, whose columns also hold the model's drawing at each sample. Without ``out`` the folder is a temporary one, removed when the interpreter exits unless ``save``d.
"""
import atexit
import html
import json
import os
import shutil
import tempfile
import warnings

import numpy as np
import pandas as pd

from . import _hybridcont as native
from . import _paths
from .models import Model

_TEMPORARY = []


@atexit.register
def _remove_temporary_folders():
    for path in _TEMPORARY:
        shutil.rmtree(path, ignore_errors=True)


def _options(model_name, out, **options):
    """The keyword arguments of ``run`` as the library takes them: each is an option the library declares
    (``native.study_options()``: keyword, kind, help) and converts and checks itself; a study or a path where a
    folder is named."""
    opts = {"model": model_name, "models_directory": _paths.MODELS, "out": out}
    for key, value in options.items():
        if isinstance(value, Study):  # from_, families_of: a saved study
            value = value.path
        opts[key] = value
    if opts.get("threads") is None:
        # As the command line: every core unless threads says otherwise (the result does not depend on it).
        opts["threads"] = max(1, os.cpu_count() or 1)
    return opts


def _options_help():
    """The options of ``run`` as the library declares them (its docstring): an RST definition list, one entry each."""
    import re
    import textwrap
    lines = []
    for spec in native.study_options():
        if spec["keyword"] in ("model", "out"):
            continue
        default = "" if spec["default"] in (None, False, "", [], {}) else " (default %r)" % (spec["default"],)
        # A keyword's trailing underscore (from_, as_) would be a reference in RST.
        text = re.sub(r"(?<=\w)_(?=\W|$)", r"\\_", spec["help"] + default)
        lines.append("    ``%s``" % spec["keyword"])
        lines.append(textwrap.fill(text, width=100, initial_indent="        ", subsequent_indent="        "))
    return "\n".join(lines)


def check(model, **options):
    """Validates ``run``'s options against the model without computing (ValueError as run raises it); returns
    the notes the study would say."""
    if isinstance(model, Model) and model.text is not None:
        raise ValueError("check: a model built in Python is checked by running it")
    name = (model.source or model.name) if isinstance(model, Model) else os.fspath(model)
    return list(native.check_options(_options(name, "", **options)))


def run(model, out=None, progress=True, report=True, **options):
    """Runs a study of ``model`` (a name, a model file's path, or a Model) and returns its Study.

    Keyword arguments are the options of ``hybridcont run`` (the library declares them; values as
    ``set={"k": 60}``, ``until={"H": 1.8}``, ``bound={"H": (0, None)}``, ``monitor={"speed": [0.5, 0.8]}``,
    ``fix={"H": 1.5}``, ``from_=`` a Study or a folder, ``families_of=`` a Study or a folder; threads default to
    every core):

{options}
    ``out``
        the results folder, e.g. ``"results/slip"`` (default: a temporary one)
    ``progress``
        True shows a bar (tqdm where installed, else lines), False nothing, or a callable
        ``f(stage, branches, points, message)`` called as the study goes.
    ``report``
        write report.html into the folder (2 MB: a sweep's grid points do without).

    Bad input raises ValueError with the library's message; a numerical failure is the study's status.
    Ctrl-C ends the study after its current step: status "cancelled", the work so far kept (and warned)."""
    if isinstance(model, Model):
        # Its source (a built-in name or a model file) where it has one: the folder then rebuilds it from there.
        native_model, name = model._native, (model.source if model.text is None and model.source else model.name)
    else:
        native_model, name = None, os.fspath(model)
    temporary = out is None
    if temporary:
        out = tempfile.mkdtemp(prefix="hybridcont-")
        _TEMPORARY.append(out)
        options["overwrite"] = True
    opts = _options(name, os.fspath(out), **options)
    if isinstance(model, Model) and model.text is not None:
        opts["model_text"] = model.text  # recorded: the folder rebuilds this model, and resume sees an edit
    on_progress, close = _progress(progress)
    try:
        # report.html written as the command line writes it, from the study in memory
        result = native.run_study(opts, native_model, on_progress, None, None,
                                  _paths.report_assets() if report else None)
    finally:
        close()
    if result["write_error"]:
        warnings.warn("the results folder could not be written whole (%s): the study is kept as far as it was "
                      "written" % result["write_error"], RuntimeWarning, stacklevel=2)
    if result["report_error"]:
        warnings.warn("report.html not written: %s" % result["report_error"], RuntimeWarning, stacklevel=2)
    if result["report_note"]:
        warnings.warn("report.html written without the orbits' animations: %s" % result["report_note"],
                      RuntimeWarning, stacklevel=2)
    study = Study(opts["out"], model=model if isinstance(model, Model) else None, result=result)
    if result["interrupted"]:
        warnings.warn("the study was interrupted: the work so far is kept (status %s)" % result["status"],
                      RuntimeWarning, stacklevel=2)
    return study


run.__doc__ = run.__doc__.replace("{options}", _options_help())


def load(path, model=None):
    """The study saved in a results folder (ValueError naming the file and field of a damaged folder)."""
    return Study(os.fspath(path), model=model)


def _progress(progress):
    """(callback, close) for run's progress argument."""
    if progress is False or progress is None:
        return None, lambda: None
    if callable(progress):
        return progress, lambda: None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        tqdm = None
    if tqdm is None:
        def say(stage, branches, points, message):
            print("%s: %d branches, %d points %s" % (stage, branches, points, message))
        return say, lambda: None
    # The number of branches is what a study discovers: no total exists in advance, so the bar counts points.
    bar = tqdm(total=None, unit=" points", desc="study", leave=False)

    def update(stage, branches, points, message):
        bar.set_description("%s, %d branches" % (stage, branches))
        bar.update(max(0, points - bar.n))
    return update, bar.close


class Study:
    """A study's results folder, read as DataFrames (attributes are read when first asked for)."""

    def __init__(self, path, model=None, result=None):
        self.path = os.path.abspath(path)
        self.model = model
        # A folder just written is the run's own; any other is checked as the library's LoadStudy checks it.
        info = result if result is not None else native.load_study(self.path)
        self.status = info["status"]
        self.message = info["message"]
        self.model_name = info["model"]
        self.version = info["version"]
        self._answer = info["answer"]
        self._families = list(info["families"])
        # The typed study's tables (the library's record, as summary.json serializes it): rows of the special
        # points (labels by the library's one rule), branches and changes of word.
        self._rows = {key: list(info[key]) for key in ("special_points", "branches", "word_changes", "curves",
                                                       "regions")}
        self._points = dict(info["points"])  # the typed points, column by column (study_table.h)
        self._unknowns = list(info["unknowns"])
        self._model_source = dict(info["model_source"])
        self.interrupted = bool(result and result["interrupted"])
        self.write_error = result["write_error"] if result else ""
        self.wall_seconds = result["wall_seconds"] if result else None
        # The saved document as the library wrote (or read and checked) it: the effective options, the presentation.
        self.summary = json.loads(info["summary_json"])
        self._cache = {}

    # ---- tables ------------------------------------------------------------------------------------------
    def _table(self, key, make):
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    @property
    def unknowns(self):
        """The names of u's entries (the layout of the branch files' unknowns and special points' u)."""
        return list(self._unknowns)

    @property
    def branches(self):
        """One row per branch: id, family, parent special point, direction, depth, points, termination, word,
        image_of, symmetry, file, then message, model, origin, continued, reflected_from, period_doubled_from and
        handed_over_from."""
        return self._table("branches", lambda: pd.DataFrame(self._rows["branches"]))

    @property
    def points(self):
        """The study's analysed points, one row per point over every branch (the typed study's, as its branch
        files hold them: docs/results-format.md): branch, family, index, H, T, the unknowns, physical,
        classification, stability, residual, newton_iterations, step, dT_d<c>, replay error, Floquet data and
        multipliers, quantities and observables."""
        def make():
            columns = self._points
            # branch, index and the counts as integers where every row has one (a table of no rows stays empty)
            frame = pd.DataFrame(columns)
            for name in ("branch", "index", "physical", "newton_iterations"):
                if name in frame and len(frame) and frame[name].notna().all():
                    frame[name] = frame[name].astype(int)
            return frame
        return self._table("points", make)

    def branch(self, id):
        """The points of one branch."""
        points = self.points
        return points[points["branch"] == id].reset_index(drop=True)

    @property
    def special_points(self):
        """One row per located (or bracketed) special point: label, id, type, branch, index, H, T, status,
        precision (also along the branch and in H), residual, component, message, u (the point in the study's
        unknowns), each free parameter or observable among the unknowns by name, and where they apply word,
        period_doubled_from, observables and extremum (an EX point's "maximum" or "minimum" of its component)."""
        return self._table("special_points", lambda: pd.DataFrame(self._rows["special_points"]))

    @property
    def families(self):
        """Where each family is physical and where stable, over all its branches (the library's one fold of
        the branches' ranges, as the one-screen answer and a sweep's table say it): one row per interval —
        family, kind ("physical" or "stable"), continued (the coordinate: H or the free parameter), from, to
        (from <= to), from_end and to_end (the special point's label at the end, or how the end is known),
        branches and special_points (the labels of the located special points on its physical stretches).
        Disjoint intervals are separate rows."""
        columns = ["family", "kind", "continued", "from", "to", "from_end", "to_end", "branches", "special_points"]
        return self._table("families", lambda: pd.DataFrame(self._families, columns=columns))

    @property
    def word_changes(self):
        """An automaton's changes of phase sequence, one row each: from_word, from_branch, at, H (H_physical and
        H_beyond where an end was only bracketed), detail, rule, to_word, residual, state_difference,
        period_difference, accepted, reason, to_branches."""
        return self._table("word_changes", lambda: pd.DataFrame(self._rows["word_changes"]))

    @property
    def curves(self):
        """The two-parameter curves (``curves=p``), one row per point: curve (its id), type, name (a boundary's
        quantity), special_point (the one it continues, -1 for a boundary), status, then H, p and the curve's
        other unknowns."""
        return self._table("curves", lambda: pd.DataFrame(self._rows["curves"]))

    @property
    def regions(self):
        """Where each family is physical and where stable in the plane of the curves (``curves=p``), one row per
        vertex of each region's polygon: region (its index), family, kind ("physical" or "stable"), branch, then p
        and the families' coordinate (H, or the free parameter)."""
        return self._table("regions", lambda: pd.DataFrame(self._rows["regions"]))

    @property
    def orbits(self):
        """The key-frame orbits, each one period as a time series (t, segment, phase, "<phase>.<state>",
        draw.<point>.x/y), with its label, branch, index, H, T and monodromy in ``frame.attrs``."""
        def make():
            out = []
            for o in self.summary.get("orbits") or []:
                frame = pd.read_csv(os.path.join(self.path, o["file"]))
                frame.attrs.update({k: v for k, v in o.items() if k != "monodromy"})
                if "monodromy" in o:
                    frame.attrs["monodromy"] = np.array(o["monodromy"], dtype=float)
                out.append(frame)
            return out
        return self._table("orbits", make)

    # ---- points ------------------------------------------------------------------------------------------
    def u(self, branch, index):
        """The point `index` of `branch` in the study's unknowns (numpy array)."""
        rows = self.branch(branch)
        row = rows[rows["index"] == index]
        if row.empty:
            raise ValueError("branch %d has no point %d" % (branch, index))
        return row.iloc[0][self.unknowns].to_numpy(dtype=float)

    def _model(self):
        """The study's own model at its parameter values: the one given, else rebuilt from the folder's record of
        it (ValueError where it cannot be: never another model of the same name)."""
        if self.model is None:
            source = self._model_source
            self.model = Model(native.model_of_study(self.path, _paths.MODELS),
                               source=source["path"] or source["name"], text=source["text"] or None)
        return self.model

    def _map(self):
        o = self.summary.get("options") or {}
        return {"free": o.get("free") or [], "fix": o.get("fixed") or {}}

    def _tolerances(self):
        """The study's integrator tolerances (its effective options): a point is evaluated as it was computed."""
        integrator = (self.summary.get("options") or {}).get("integrator") or {}
        return {"rtol": integrator.get("rtol"), "atol": integrator.get("atol")}

    def evaluate(self, branch, index, jacobian=True):
        """r and dr of the time-based map at a point of the study (Model.evaluate)."""
        return self._model().evaluate(self.u(branch, index), jacobian=jacobian, **self._map(), **self._tolerances())

    def floquet(self, branch, index):
        """The monodromy matrix and Floquet multipliers at a point of the study (Model.floquet)."""
        return self._model().floquet(self.u(branch, index), **self._map(), **self._tolerances())

    def monodromy(self, branch, index):
        """Φ_T at a point of the study."""
        return self.floquet(branch, index)["monodromy"]

    def orbit(self, branch, index, samples=400):
        """One period of the orbit at a point of the study, as a time series (Model.orbit)."""
        u = self.u(branch, index)
        m = self._model()
        free = self._map()["free"]
        if free:
            m = m.with_parameters(**{p: u[self.unknowns.index(p)] for p in free})
            u = u[: len(u) - len(free)]
        return m.orbit(u, samples, **self._tolerances())

    # ---- restart, save ----------------------------------------------------------------------------------
    def continue_from(self, label, as_="auto", out=None, progress=True, **options):
        """A new study from a labelled point of this one ("PD4", "SB1", "B5", "B5:12"; ``as_`` as --as:
        continue, switch, period-doubled, curve, free), with the options of ``run``."""
        # The study's own model (given, or rebuilt from the folder's record of it): never another of its name.
        return run(self._model(), out=out, progress=progress, from_=self, at=label, as_=as_, **options)

    def save(self, path, overwrite=False):
        """Copies the results folder to path (refused where a folder is, unless overwrite); returns the saved
        Study."""
        path = os.path.abspath(os.fspath(path))
        if os.path.realpath(path) == os.path.realpath(self.path):
            raise ValueError("save '%s': that is the study's own folder" % path)
        if os.path.exists(path):
            if not overwrite:
                raise ValueError("save '%s': the folder exists (overwrite=True replaces it)" % path)
            shutil.rmtree(path)
        shutil.copytree(self.path, path)
        return Study(path, model=self.model)

    # ---- pictures ----------------------------------------------------------------------------------------
    def diagram(self, x=None, y="T", ax=None):
        """The bifurcation diagram as a matplotlib figure (returned; nothing is written): column ``y`` over column
        ``x`` (default: the coordinate the families are continued in) of every branch, its physical stretches in
        its family's colour (thick where stable), the rest thin and grey, and the located special points of the
        physical stretches labelled at their markers. ``ax``: draw into these axes instead of a new figure."""
        import matplotlib.pyplot as plt
        points = self.points
        if x is None:
            x = self._rows["branches"][0]["continued"] if self._rows["branches"] else "H"
        for column in (x, y):
            if column not in points.columns:
                raise ValueError("diagram: no column '%s' (the points have %s)" % (column, ", ".join(points.columns)))
        if ax is None:
            fig, ax = plt.subplots(figsize=(7.0, 4.4))
        else:
            fig = ax.figure
        families = sorted({f for f in points["family"] if isinstance(f, str) and f})
        colours = dict(zip(families, plt.rcParams["axes.prop_cycle"].by_key()["color"] * 4))
        labelled = set()
        for _, branch in points.groupby("branch"):
            ax.plot(branch[x], branch[y], color="0.75", lw=0.8, zorder=1)
            physical = branch["physical"].astype(bool)
            stable = physical & (branch["stable"].astype(str).str.lower().isin(["1", "true", "1.0"]))
            for mask, width in ((physical, 1.6), (stable, 3.0)):
                part = branch[x].where(mask), branch[y].where(mask)
                family = next((f for f in branch["family"] if isinstance(f, str) and f), None)
                label = family if width < 2 and family and family not in labelled else None
                if label:
                    labelled.add(family)
                ax.plot(*part, color=colours.get(family, "0.3"), lw=width, zorder=2, label=label)
        # Located special points on physical stretches; points that coincide share one marker and one label.
        physical_at = {(b, i) for b, i, ph in zip(points["branch"], points["index"], points["physical"]) if ph}
        marks = {}
        for _, sp in self.special_points.iterrows():
            if sp["status"] != "located" or sp["type"] == "start" or x not in sp or y not in sp:
                continue
            xv, yv = sp.get(x), sp.get(y)
            on_physical = (sp["branch"], sp["index"]) in physical_at or (sp["branch"], sp["index"] + 1) in physical_at
            if not (on_physical and np.isfinite(xv) and np.isfinite(yv)):
                continue
            key = (round(float(xv), 6), round(float(yv), 6))
            marks.setdefault(key, (xv, yv, []))[2].append(sp["label"])
        for xv, yv, labels in marks.values():
            ax.plot([xv], [yv], "o", ms=4, mfc="white", mec="black", zorder=3)
            ax.annotate(" = ".join(labels), (xv, yv), textcoords="offset points", xytext=(4, 4), fontsize=7)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.grid(True, color="0.92", lw=0.6)
        if labelled:
            ax.legend(fontsize=8, frameon=False)
        ax.set_title("%s: %s over %s (thick: stable)" % (self.model_name, y, x), fontsize=10)
        return fig

    def plot(self, x=None, y=None, svg=False, pdf=False, all=False):
        """The figures of ``hybridcont plot`` written into the folder (or, with x and y, the diagram of column
        y over column x); returns their paths."""
        import importlib.util
        import contextlib
        import io
        spec = importlib.util.spec_from_file_location("hybridcont_plot", _paths.PLOT_SCRIPT)
        script = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(script)
        argv = [self.path] + (["--svg"] if svg else []) + (["--pdf"] if pdf else []) + (["--all"] if all else [])
        if (x is None) != (y is None):
            raise ValueError("plot: x and y go together (the two columns of one diagram)")
        if x is not None:
            argv += ["--x", x, "--y", y]
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = script.main(argv)
        if rc == 2:
            raise ValueError(err.getvalue().strip())
        if err.getvalue().strip():
            warnings.warn(err.getvalue().strip(), RuntimeWarning, stacklevel=2)
        return [line for line in out.getvalue().splitlines() if line]

    def report_html(self):
        """report.html of the study: one self-contained page (its diagram, orbits, multipliers, tables)."""
        m = self.model._native if isinstance(self.model, Model) else None
        return native.report_html(self.path, _paths.report_assets(), m, _paths.MODELS)

    def _repr_html_(self):
        # The report in an iframe of its own: its scripts and styles do not meet the notebook's.
        return ('<iframe srcdoc="%s" style="width: 100%%; height: 900px; border: 1px solid #ddd"></iframe>'
                % html.escape(self.report_html(), quote=True))

    def __str__(self):
        return self._answer

    def __repr__(self):
        n_families = len({row["family"] for row in self._families})
        return "<hybridcont.Study %s: %d branches, %d families, %d special points, %s; %s>" % (
            self.model_name, len(self._rows["branches"]), n_families, len(self._rows["special_points"]),
            self.status, self.path)
